#include "image_facts.hpp"

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

Result<ImageFacts> image_facts(std::span<const unsigned char> bytes, const std::string& name) {
  ImageFacts facts;
  facts.bytes = bytes.size();
  facts.format = format_of(bytes);
  if (facts.format.empty()) return Error{name, "not a PNG, JPEG, WebP or KTX2 image"};
  if (facts.format == "ktx2") {
    auto texture = ktx2::read(bytes, name);
    if (!texture) return texture.error();
    facts.width = texture->width, facts.height = texture->height;
    facts.levels = std::uint32_t(texture->levels.size());
    facts.codec = ktx2_codec(*texture);
    facts.supercompression = supercompression_name(texture->supercompression);
    return facts;
  }
  auto layout = image::probe_image_bytes(bytes, name);
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
