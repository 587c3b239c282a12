#pragma once
// tinygltf behind one call that keeps it inside the folder of the file being loaded: buffer and
// image URIs that are absolute, climb above the folder with .. or name another scheme are refused,
// and the error says which URI; a file whose real path (symbolic links followed) leaves the folder
// is not read. Images must exist but are not decoded.
#include <tiny_gltf.h>

#include <filesystem>

#include "matbake/output_check.hpp"
#include "matbake/result.hpp"

namespace matbake::gltf {

// glTF text (a GLB's JSON, its buffer 0 named kGlbBinUri and `glb_bin` its BIN chunk at the
// buffer's byteLength, which tinygltf then takes over without copying it). Errors name `path` as
// given; buffers and images are looked up beside it. Only the files of `buffer_uris` are read; an
// image file is checked (confined, a regular file) and never read: inspect of a glTF with a 512 MB
// image read all of it.
inline constexpr const char* kGlbBinUri = "\x01glb-bin";
// A buffer of one zero byte (what a meshopt fallback buffer, which has none, is given to tinygltf as).
inline constexpr const char* kEmptyBufferUri = "\x01empty";
Status load_model_json(const std::filesystem::path& path, const std::string& json_text, std::vector<unsigned char>& glb_bin,
                       const std::vector<std::string>& buffer_uris, tinygltf::Model& model);

// Whether `path` lies inside `base`, lexically.
bool is_inside(const std::filesystem::path& base, const std::filesystem::path& path);
// (matbake::is_really_inside, output_check.hpp, judges real paths: a link beside the glTF to a file
// elsewhere is outside.)

}  // namespace matbake::gltf
