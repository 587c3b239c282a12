#pragma once
// `matbake inspect PATH` (docs/inspect.md): what a file holds, read without building. A glTF's
// scenes, meshes (triangles, attributes, compression, quantization), materials (workflow, slots,
// extensions), textures (slot, class, size, format, codec, levels, bytes, GPU memory) and images
// (shared or duplicated); a KTX2 file's header, data format descriptor and levels; a manifest's
// jobs with their state from the stamps and what they would write. One JSON value, whose schema
// is docs/inspect.schema.json; the terminal's tables are made from it.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "matbake/result.hpp"

namespace matbake::inspect {

// By the file's kind: .gltf/.glb, .ktx2, .toml (a manifest); anything else is refused.
Result<nlohmann::json> inspect(const std::filesystem::path& path);

Result<nlohmann::json> inspect_gltf(const std::filesystem::path& path);
Result<nlohmann::json> inspect_ktx2(const std::filesystem::path& path);
Result<nlohmann::json> inspect_manifest(const std::filesystem::path& path);

// The bytes a texture of `width` × `height` takes on a GPU with `levels` mip levels (0: the full
// chain to 1 × 1, as a runtime makes for a PNG), uncompressed RGBA8 and in 4 × 4 blocks of 16 bytes
// (BC7 and ASTC 4×4, what a KTX2 texture is transcoded to).
struct GpuBytes {
  std::uint64_t rgba8 = 0;
  std::uint64_t block_4x4 = 0;
};
GpuBytes gpu_bytes(std::uint32_t width, std::uint32_t height, std::uint32_t levels);

// The JSON as tables for a terminal.
std::string text(const nlohmann::json& inspected);

}  // namespace matbake::inspect
