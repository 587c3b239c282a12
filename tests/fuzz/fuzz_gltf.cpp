// glTF loading: the document (JSON, buffers, accessor checks) and the flattened scene built from it,
// as export and bake-ao read them. MATBAKE_FUZZ_EXTENSION is ".gltf" or ".glb" (two targets).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "lib/src/gltf/document.hpp"
#include "lib/src/scene/from_document.hpp"

namespace {

std::filesystem::path scratch;  // a folder of this process's own: the input is a file in it

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  scratch = std::filesystem::temp_directory_path() / ("matbake-fuzz-" + std::to_string(getpid()));
  std::filesystem::create_directories(scratch);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = scratch / (std::string("input") + MATBAKE_FUZZ_EXTENSION);
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  auto doc = matbake::gltf::read_document(file);
  if (!doc) return 0;
  (void)matbake::scene::scene_from_document(*doc);
  for (std::size_t i = 0; doc->json.contains("images") && doc->json["images"].is_array() && i < doc->json["images"].size(); ++i) {
    (void)matbake::gltf::image_bytes(*doc, i);
  }
  return 0;
}
