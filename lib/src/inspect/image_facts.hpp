#pragma once
// An image's format, size, levels and codec, from its header alone (a KTX2 file's level index).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <vector>
#include <span>
#include <string>

#include "matbake/ktx2.hpp"
#include "matbake/result.hpp"

namespace matbake::inspect {

struct ImageFacts {
  std::string format;  // png, jpeg, webp, ktx2
  std::string codec;   // png, jpeg, webp; a KTX2's etc1s, uastc or vk-format-N
  std::string supercompression;  // KTX2: none, basislz, zstd, other-N; else empty
  std::uint32_t width = 0, height = 0;
  std::uint32_t levels = 1;  // stored; a runtime makes the rest of a PNG's chain
  std::uint64_t bytes = 0;
};

// An image file's leading bytes and its size: what inspect reads of a file, so that its memory and
// time do not grow with the file (a KTX2 file's header part, up to 16 MiB; 4 MiB of others, room
// for a JPEG's metadata before its frame header).
struct ImageHead {
  std::vector<unsigned char> bytes;
  std::uint64_t size = 0;  // the whole file's
};
Result<ImageHead> read_head(const std::filesystem::path& file);

// The facts of an image from its leading bytes `head` (all of it, or a read_head) and its size.
Result<ImageFacts> image_facts(std::span<const unsigned char> head, std::uint64_t size, const std::string& name);
// A KTX2 file's header, index and descriptors (no level's bytes) from its leading bytes.
Result<ktx2::Texture> ktx2_header(std::span<const unsigned char> head, std::uint64_t size, const std::string& name);
// Its fields, with GPU memory by formula (gpu_bytes): a KTX2 with its stored levels, other formats
// with the full chain a runtime makes.
nlohmann::json facts_json(const ImageFacts& facts);

// The codec a KTX2 texture's descriptor names, and its supercompression.
std::string ktx2_codec(const ktx2::Texture& texture);
std::string supercompression_name(std::uint32_t scheme);

// The file's totals from its entries: triangles of the default scene, vertices, image bytes, and
// GPU memory of the textures (each by the source a runtime with KTX2 support picks).
nlohmann::json totals_json(const nlohmann::json& inspected);

}  // namespace matbake::inspect
