#include "image_facts.hpp"

#include <algorithm>
#include <fstream>

#include <cstring>
#include <set>

#include "matbake/image.hpp"
#include "matbake/inspect.hpp"

namespace matbake::inspect {
namespace {

bool starts_with(std::span<const unsigned char> bytes, std::string_view signature, std::size_t at = 0) {
  return bytes.size() >= at + signature.size() && std::memcmp(bytes.data() + at, signature.data(), signature.size()) == 0;
}

std::string format_of(std::span<const unsigned char> bytes) {
  if (starts_with(bytes, "\x89PNG\r\n\x1a\n")) return "png";
  if (starts_with(bytes, "\xff\xd8\xff")) return "jpeg";
  if (starts_with(bytes, "RIFF") && starts_with(bytes, "WEBP", 8)) return "webp";
  if (starts_with(bytes, "\xabKTX 20\xbb\r\n\x1a\n")) return "ktx2";
  return "";
}

}  // namespace

std::string supercompression_name(std::uint32_t scheme) {
  switch (scheme) {
    case ktx2::kSupercompressionNone: return "none";
    case ktx2::kSupercompressionBasisLZ: return "basislz";
    case ktx2::kSupercompressionZstd: return "zstd";
    default: return "other-" + std::to_string(scheme);
  }
}

std::string ktx2_codec(const ktx2::Texture& texture) {
  if (texture.descriptor.model == ktx2::kModelETC1S) return "etc1s";
  if (texture.descriptor.model == ktx2::kModelUASTC) return "uastc";
  return "vk-format-" + std::to_string(texture.vk_format);
}

namespace {
constexpr std::uint64_t kHeadBytes = 4u << 20, kMostKtx2HeaderBytes = 16u << 20;

bool read_at_start(std::ifstream& in, std::vector<unsigned char>& bytes) {
  in.clear();
  in.seekg(0);
  return bool(in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())));
}
}  // namespace

Result<ImageHead> read_head(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return Error{file.string(), "cannot be read"};
  ImageHead head;
  head.size = std::uint64_t(in.tellg());
  head.bytes.resize(std::min(head.size, kHeadBytes));
  if (!read_at_start(in, head.bytes)) return Error{file.string(), "cannot be read"};
  const std::uint64_t extent = ktx2::header_extent(head.bytes);
  if (extent > head.bytes.size() && extent <= std::min(head.size, kMostKtx2HeaderBytes)) {
    head.bytes.resize(extent);
    if (!read_at_start(in, head.bytes)) return Error{file.string(), "cannot be read"};
  }
  return head;
}

Result<ktx2::Texture> ktx2_header(std::span<const unsigned char> head, std::uint64_t size, const std::string& name) {
  const std::uint64_t extent = ktx2::header_extent(head);
  if (extent > size) return Error{name, "KTX2 index points past the end of the file"};
  if (extent > head.size()) return Error{name, "KTX2 header data of " + std::to_string(extent) + " bytes, more than inspect reads"};
  return ktx2::read_header(head, size, name);
}

Result<ImageFacts> image_facts(std::span<const unsigned char> head, std::uint64_t size, const std::string& name) {
  ImageFacts facts;
  facts.bytes = size;
  facts.format = format_of(head);
  if (facts.format.empty()) return Error{name, "not a PNG, JPEG, WebP or KTX2 image"};
  if (facts.format == "ktx2") {
    auto texture = ktx2_header(head, size, name);
    if (!texture) return texture.error();
    facts.width = texture->width, facts.height = texture->height;
    facts.levels = std::uint32_t(texture->levels.size());
    facts.codec = ktx2_codec(*texture);
    facts.supercompression = supercompression_name(texture->supercompression);
    return facts;
  }
  auto layout = image::probe_image_bytes(head, name);
  if (!layout) return layout.error();
  facts.width = std::uint32_t(layout->width), facts.height = std::uint32_t(layout->height);
  facts.codec = facts.format;
  return facts;
}

nlohmann::json facts_json(const ImageFacts& facts) {
  const GpuBytes gpu = gpu_bytes(facts.width, facts.height, facts.format == "ktx2" ? facts.levels : 0);
  nlohmann::json out = {{"format", facts.format}, {"codec", facts.codec},   {"width", facts.width},
                        {"height", facts.height}, {"levels", facts.levels}, {"bytes", facts.bytes},
                        {"gpu_bytes", {{"rgba8", gpu.rgba8}, {"block_4x4", gpu.block_4x4}}}};
  if (!facts.supercompression.empty()) out["supercompression"] = facts.supercompression;
  return out;
}

nlohmann::json totals_json(const nlohmann::json& inspected) {
  std::uint64_t triangles = 0, vertices = 0, image_bytes = 0, rgba8 = 0, block = 0;
  for (const auto& scene : inspected["scenes"]) {
    if (scene["default"].get<bool>()) triangles = scene["triangles"].get<std::uint64_t>();
  }
  for (const auto& mesh : inspected["meshes"]) vertices += mesh["vertices"].get<std::uint64_t>();
  for (const auto& image : inspected["images"]) image_bytes += image["bytes"].get<std::uint64_t>();
  std::set<std::uint64_t> counted;  // an image two textures share is on the GPU once
  for (const auto& texture : inspected["textures"]) {
    const auto& sources = texture["sources"];
    if (sources.empty()) continue;
    const nlohmann::json* picked = &sources[0];
    for (const auto& s : sources) {
      if (s["via"] == "KHR_texture_basisu") picked = &s;
    }
    if (!counted.insert((*picked)["image"].get<std::uint64_t>()).second) continue;
    rgba8 += (*picked)["gpu_bytes"]["rgba8"].get<std::uint64_t>();
    block += (*picked)["gpu_bytes"]["block_4x4"].get<std::uint64_t>();
  }
  return {{"triangles", triangles}, {"vertices", vertices}, {"image_bytes", image_bytes},
          {"gpu_bytes", {{"rgba8", rgba8}, {"block_4x4", block}}}};
}

}  // namespace matbake::inspect
