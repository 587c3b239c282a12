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

// .glb by extension, else .gltf. Errors name `path` as given.
Status load_model(const std::filesystem::path& path, tinygltf::Model& model);
// The same from the file's bytes, already read (buffers and images are still looked up beside it).
Status load_model(const std::filesystem::path& path, const std::string& bytes, tinygltf::Model& model);
// A GLB's JSON as glTF text, its buffer 0 named kGlbBinUri and `glb_bin` its BIN chunk (at the
// buffer's byteLength), which tinygltf then takes over without copying it.
inline constexpr const char* kGlbBinUri = "\x01glb-bin";
Status load_model_json(const std::filesystem::path& path, const std::string& json_text, std::vector<unsigned char>& glb_bin,
                       tinygltf::Model& model);

// Whether `path` lies inside `base`, lexically.
bool is_inside(const std::filesystem::path& base, const std::filesystem::path& path);
// (matbake::is_really_inside, output_check.hpp, judges real paths: a link beside the glTF to a file
// elsewhere is outside.)

}  // namespace matbake::gltf
