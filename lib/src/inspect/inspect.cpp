// `matbake inspect`: the file's kind, a KTX2 file's fields, GPU memory by formula.
#include <algorithm>

#include "image_facts.hpp"
#include "matbake/inspect.hpp"
#include "matbake/read_file.hpp"

namespace matbake::inspect {
namespace fs = std::filesystem;
namespace {

std::string transfer_name(std::uint8_t transfer) {
  return transfer == ktx2::kTransferSRGB ? "srgb" : transfer == ktx2::kTransferLinear ? "linear" : "other-" + std::to_string(transfer);
}

std::string primaries_name(std::uint8_t primaries) {
  return primaries == ktx2::kPrimariesBT709 ? "bt709" : primaries == ktx2::kPrimariesUnspecified ? "unspecified"
                                                                                                 : "other-" + std::to_string(primaries);
}

// A key/value pair's value as text when it is printable, else its length.
nlohmann::json key_value(const std::string& value) {
  const bool printable = std::all_of(value.begin(), value.end(), [](unsigned char c) { return c >= 0x20 && c < 0x7f; });
  return printable ? nlohmann::json(value) : nlohmann::json("<" + std::to_string(value.size()) + " bytes>");
}

}  // namespace

GpuBytes gpu_bytes(std::uint32_t width, std::uint32_t height, std::uint32_t levels) {
  GpuBytes total;
  std::uint64_t w = std::max(1u, width), h = std::max(1u, height);
  for (std::uint32_t level = 0; levels == 0 || level < levels; ++level) {
    total.rgba8 += w * h * 4;
    total.block_4x4 += ((w + 3) / 4) * ((h + 3) / 4) * 16;
    if (w == 1 && h == 1) break;
    w = std::max<std::uint64_t>(1, w / 2), h = std::max<std::uint64_t>(1, h / 2);
  }
  return total;
}

Result<nlohmann::json> inspect_ktx2(const fs::path& path) {
  auto head = read_head(path);
  if (!head) return head.error();
  const std::uint64_t file_size = head->size;
  auto texture = ktx2_header(head->bytes, file_size, path.string());
  if (!texture) return texture.error();
  const ktx2::Descriptor& d = texture->descriptor;
  nlohmann::json levels = nlohmann::json::array();
  for (std::size_t i = 0; i < texture->levels.size(); ++i) {
    levels.push_back({{"level", i},
                      {"width", std::max(1u, texture->width >> i)},
                      {"height", std::max(1u, texture->height >> i)},
                      {"bytes", texture->levels[i].byte_length},
                      {"uncompressed_bytes", texture->levels[i].uncompressed_length}});
  }
  nlohmann::json key_values = nlohmann::json::object();
  for (const auto& [key, value] : texture->key_values) key_values[key] = key_value(value);
  const GpuBytes gpu = gpu_bytes(texture->width, texture->height, std::uint32_t(texture->levels.size()));
  return nlohmann::json{
      {"kind", "ktx2"},
      {"file", path.string()},
      {"bytes", file_size},
      {"header",
       {{"vk_format", texture->vk_format},
        {"type_size", texture->type_size},
        {"width", texture->width},
        {"height", texture->height},
        {"levels", texture->levels.size()},
        {"supercompression", supercompression_name(texture->supercompression)}}},
      {"descriptor",
       {{"codec", ktx2_codec(*texture)},
        {"color_model", d.model},
        {"primaries", primaries_name(d.primaries)},
        {"transfer", transfer_name(d.transfer)},
        {"alpha_premultiplied", (d.flags & 1) != 0},
        {"block", {d.block_width, d.block_height}},
        {"channels", d.channels}}},
      {"levels", levels},
      {"key_values", key_values},
      {"global_data_bytes", texture->global_data.size()},
      {"gpu_bytes", {{"rgba8", gpu.rgba8}, {"block_4x4", gpu.block_4x4}}}};
}

Result<nlohmann::json> inspect(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Error{path.string(), ec ? ec.message() : "not a file"};
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".gltf" || ext == ".glb") return inspect_gltf(path);
  if (ext == ".ktx2") return inspect_ktx2(path);
  if (ext == ".toml") return inspect_manifest(path);
  return Error{path.string(), "matbake inspects .gltf, .glb, .ktx2 and manifests (.toml)"};
}

}  // namespace matbake::inspect
