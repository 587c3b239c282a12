#pragma once
// The delivery pass over a document about to be written (export, bake-ao, a build's scenes): every
// texture a material uses, by the class of the slot it fills, resized and encoded as the options say.
#include <filesystem>
#include <vector>

#include "../gltf/texture_files.hpp"
#include "matbake/delivery.hpp"
#include "matbake/stage.hpp"

namespace matbake::delivery {

// Whether the pass changes anything: KTX2 asked for, or a size setting.
bool changes_textures(const Options& options);

// The format of the textures a scene's writer makes before delivery (KTX2 is made from PNG).
gltf::MadeFormat made_format(const Options& options);

// Rewrites `doc`'s used textures: KTX2 (KHR_texture_basisu) when the texture format is
// ktx2 and the class's codec is not png, else resized PNG/WebP when the sizes say so. Scratch files go
// beside `output`. Textures already KTX2 are kept. Call store_once afterwards: replaced images are
// left unreferenced. The cache's decoded images are dropped; each texture is decoded in its turn.
// `stage` is told how many textures are made.
Result<std::vector<TextureReport>> deliver_textures(gltf::Document& doc, gltf::ImageCache& cache, const Options& options,
                                                    const std::filesystem::path& output, const StageReport& stage = {});

// What deliver_textures would make of each used texture, with nothing decoded or encoded: class,
// source, needed and delivered sizes, codec and levels as it would choose them, the source image's
// bytes, and `bytes` estimated (estimated_bytes; 0 for a texture made as one file with another).
// Textures it would keep have their note. The same choices as deliver_textures, made by the same code.
Result<std::vector<TextureReport>> plan_textures(const gltf::Document& doc, const gltf::ImageCache& cache, const Options& options);

// The document as it will be written: identical images stored once (and textures that then match
// merged), what nothing reaches removed (gltf::prune_unreachable; its lines returned), and `reports`
// renumbered to the written textures (a texture delivered twice under two indices is one report,
// with both's materials).
std::vector<std::string> store_once(gltf::Document& doc, std::vector<TextureReport>& reports);

}  // namespace matbake::delivery
