#pragma once
// Texture-space AO written into a glTF document: for each material the default scene reaches, an
// occlusion texture over its primitives' UVs (ao::bake_textures), as a new linear PNG that becomes
// the material's occlusionTexture (the file's own one multiplied in, or replaced).
#include <string>
#include <vector>

#include "../gltf/document.hpp"
#include "../gltf/texture_files.hpp"
#include "matbake/ao.hpp"
#include "matbake/bake_ao.hpp"

namespace matbake::bake_ao {

// The materials the scene's instances use, each a texture target (UV set and wrap modes from the
// request and the material's occlusionTexture), and what cannot be baked (instances without a
// material; a mesh placed by several nodes sharing a material, averaged) as notes.
struct OcclusionTargets {
  std::vector<int> materials;
  std::vector<int> nodes;  // with per_instance, the node placing the target's instances; else -1
  std::vector<ao::TextureTarget> targets;
  std::vector<std::string> notes;
};
Result<OcclusionTargets> occlusion_targets(const gltf::Document& doc, const scene::Scene& scene,
                                           const ao::TextureRequest& request);

// Where bake_file's --dump-texture puts material `material`'s float EXR.
std::filesystem::path dumped_texture(const std::filesystem::path& folder, const std::string& stem, int material);

// Where a material's baked occlusion goes.
enum class OcclusionInto {
  texture,  // its own linear PNG (8 or 16 bits), the material's occlusionTexture
  orm,      // the red channel of a new ORM texture with the material's metallic-roughness texture
            // (same texCoord) in green and blue, at that texture's size; where the material has
            // none, its own texture as above
};

// Bakes and writes the textures into `doc` (with per_instance, into a copy of the material for each
// further placement, see occlusion_texture.cpp) (new files `<stem>_occlusion_<material>.png` or
// `<stem>_orm_ao_<material>.png`, encoded as `cache` says); the dump folder, when asked, gets each bake
// as float EXR. `cache` is the document's: a metallic-roughness texture it decoded is not decoded again.
Result<std::vector<TextureReport>> bake_occlusion_textures(gltf::Document& doc, const scene::Scene& scene,
                                                           gltf::ImageCache& cache, const ao::Request& request,
                                                           const OcclusionTargets& targets,
                                                           const std::string& stem, OcclusionInto into,
                                                           ao::TextureBakes& timing, const StageReport& stage = {});

}  // namespace matbake::bake_ao
