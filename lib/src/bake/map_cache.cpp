#include "map_cache.hpp"

#include <xxhash.h>

#include <cstring>

#include "matbake/ao_params.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/bake_params.hpp"
#include "matbake/read_file.hpp"
#include "matbake/version.hpp"
#include "../io/bounded_json.hpp"

namespace matbake::bake {
namespace fs = std::filesystem;
namespace {

constexpr int kForm = 2;  // 2: the trace's rays, misses, starts inside and probes' reach
constexpr std::uintmax_t kIndexLimit = 1u << 20;  // a few hundred bytes a target and map

std::string hex128(XXH128_hash_t hash) {
  XXH128_canonical_t canonical;
  XXH128_canonicalFromHash(&canonical, hash);
  static const char* digits = "0123456789abcdef";
  std::string text;
  for (unsigned char byte : canonical.digest) {
    text += digits[byte >> 4];
    text += digits[byte & 15];
  }
  return text;
}

std::string text_hash(const std::string& text) { return hex128(XXH3_128bits(text.data(), text.size())); }

fs::path index_file(const fs::path& folder) { return folder / "maps.json"; }
fs::path map_file(const fs::path& folder, Map map, std::size_t target) {
  return folder / (std::to_string(target) + "_" + std::string(name_in(kMapNames, map)) + ".f32");
}

// The index as stored, or an empty one: too large, not JSON, another form or shape.
nlohmann::json read_index(const fs::path& folder) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(index_file(folder), ec);
  std::string text;
  if (ec || size > kIndexLimit || !read_whole_file(index_file(folder), text)) return nlohmann::json::object();
  std::string problem;  // too deep or not JSON: as none (the maps are traced again)
  nlohmann::json index = parse_bounded_json<nlohmann::json>(text, kIndexLimit, problem);
  // Compared as JSON: value("form", 0) throws on a form of another type (found by fuzz_cache).
  if (!index.is_object() || !index.contains("form") || index["form"] != kForm) return nlohmann::json::object();
  return index;
}

bool text_at(const nlohmann::json& j, const char* key, const std::string& expected) {
  return j.is_object() && j.contains(key) && j[key].is_string() && j[key].get<std::string>() == expected;
}

}  // namespace

nlohmann::json map_parameters(std::optional<Map> map, const Request& request) {
  nlohmann::json p = params::to_json(request_params(), request);
  // Another map asked or dropped changes none of the others; the vertex maps are never kept.
  // max_misses judges a trace, bits and map_format write it: none changes one.
  for (const char* unread : {"maps", "vertex_maps", "vertex_ao_into", "vertex_existing_colors", "max_misses", "bits", "map_format"}) {
    p.erase(unread);
  }
  const bool tangent = map == Map::normal || map == Map::bent_normal;
  if (!tangent) p.erase("green");
  if (map != Map::id) p.erase("id_by");
  if (map != Map::normal) p.erase("high_normal_maps");
  const bool secondary = map == Map::ao || map == Map::bent_normal || map == Map::thickness;
  if (!secondary || request.bake.match != Match::by_name) p.erase("occluders");
  if (secondary) p["ao"] = params::to_json(ao::estimator_params(), request.occlusion);
  p["matbake"] = version;
  return p;
}

Result<std::string> inputs_hash(std::span<const fs::path> files) {
  std::string digests;
  for (const fs::path& file : files) {
    std::string bytes;
    if (!read_whole_file(file, bytes)) return Error{file.string(), "cannot be read"};
    digests += file.filename().string() + "\n" + hex128(XXH3_128bits(bytes.data(), bytes.size())) + "\n";
  }
  return text_hash(digests);
}

std::string map_key(const std::string& inputs, std::optional<Map> map, const Request& request, const std::string& targets) {
  const std::string name = map ? std::string(name_in(kMapNames, *map)) : "trace";
  return text_hash(inputs + "\n" + targets + "\n" + name + "\n" + map_parameters(map, request).dump());
}

std::optional<KeptMap> load_map(const fs::path& folder, Map map, const std::string& key, std::size_t targets, int width,
                                int height) {
  const nlohmann::json index = read_index(folder);
  const nlohmann::json maps = index.value("maps", nlohmann::json::object());  // any JSON at all: checked before it is read
  const nlohmann::json entry = maps.is_object() ? maps.value(std::string(name_in(kMapNames, map)), nlohmann::json()) : nlohmann::json();
  if (!text_at(entry, "key", key) || !entry.contains("files") || !entry["files"].is_array() || entry["files"].size() != targets) {
    return std::nullopt;
  }
  KeptMap kept;
  const std::size_t floats = std::size_t(width) * std::size_t(height) * std::size_t(channels(map));
  for (std::size_t t = 0; t < targets; ++t) {
    const fs::path file = map_file(folder, map, t);
    std::error_code ec;
    if (fs::file_size(file, ec) != floats * sizeof(float) || ec) return std::nullopt;  // before any allocation
    std::string bytes;
    if (!read_whole_file(file, bytes) || bytes.size() != floats * sizeof(float)) return std::nullopt;
    if (!text_at(entry["files"][t], "hash", hex128(XXH3_128bits(bytes.data(), bytes.size())))) return std::nullopt;
    MapImage& image = kept.images.emplace_back();
    image.map = map, image.channels = channels(map);
    image.values.resize(floats);
    std::memcpy(image.values.data(), bytes.data(), bytes.size());
  }
  return kept;
}

std::optional<Bake> load_trace(const fs::path& folder, const std::string& key, std::size_t targets) {
  const nlohmann::json trace = read_index(folder).value("trace", nlohmann::json());
  if (!text_at(trace, "key", key) || !trace.contains("targets") || !trace["targets"].is_array() || trace["targets"].size() != targets) {
    return std::nullopt;
  }
  // A field of another type reads as 0 (the maps, checked by hash, are what matters).
  const auto count = [](const nlohmann::json& j, const char* k) {
    return j.is_object() && j.value(k, nlohmann::json()).is_number_unsigned() ? j[k].get<std::size_t>() : 0;
  };
  const auto number = [](const nlohmann::json& j, const char* k) {
    return j.is_object() && j.value(k, nlohmann::json()).is_number() ? j[k].get<double>() : 0.0;
  };
  Bake out;
  const nlohmann::json boxes = trace.value("boxes", nlohmann::json());
  out.boxes = {number(boxes, "low_diagonal"), number(boxes, "high_diagonal"), number(boxes, "overlap")};
  for (const nlohmann::json& t : trace["targets"]) {
    if (!t.is_object()) return std::nullopt;
    TextureBake& b = out.textures.emplace_back();
    b.texels = count(t, "texels"), b.missed_texels = count(t, "missed_texels"), b.padded = count(t, "padded");
    b.samples = count(t, "rays"), b.misses = count(t, "misses"), b.occlusion_rays = count(t, "occlusion_rays");
    b.from_inside = count(t, "from_inside"), b.overlapped = count(t, "overlapped"), b.outside_tile = count(t, "outside_tile");
    b.faced_away = count(t, "faced_away"), b.degenerate_uv = count(t, "degenerate_uv"), b.too_large = count(t, "too_large");
    b.height_min = number(t, "height_min"), b.height_max = number(t, "height_max");
    b.reach_front = number(t, "reach_front"), b.reach_back = number(t, "reach_back");
  }
  return out;
}

Status store_maps(const fs::path& folder, const Bake& bake, const std::string& trace_key,
                  const std::vector<std::pair<Map, std::string>>& keys) {
  const std::vector<TextureBake>& baked = bake.textures;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) return Error{folder.string(), "cannot make the folder of kept maps: " + ec.message()};
  nlohmann::json index = read_index(folder);
  index["form"] = kForm;
  if (!index.contains("maps") || !index["maps"].is_object()) index["maps"] = nlohmann::json::object();
  for (const auto& [map, key] : keys) {
    const std::string name(name_in(kMapNames, map));
    index["maps"].erase(name);  // until its files are written
  }
  nlohmann::json stats = nlohmann::json::array();
  for (const TextureBake& t : baked) {
    stats.push_back({{"texels", t.texels}, {"missed_texels", t.missed_texels}, {"padded", t.padded},
                     {"height_min", t.height_min}, {"height_max", t.height_max}, {"rays", t.samples}, {"misses", t.misses},
                     {"occlusion_rays", t.occlusion_rays}, {"from_inside", t.from_inside}, {"overlapped", t.overlapped},
                     {"outside_tile", t.outside_tile}, {"reach_front", t.reach_front}, {"reach_back", t.reach_back},
                     {"faced_away", t.faced_away}, {"degenerate_uv", t.degenerate_uv}, {"too_large", t.too_large}});
  }
  const nlohmann::json boxes = {{"low_diagonal", bake.boxes.low_diagonal}, {"high_diagonal", bake.boxes.high_diagonal},
                                {"overlap", bake.boxes.overlap}};
  index["trace"] = {{"key", trace_key}, {"targets", stats}, {"boxes", boxes}};
  if (Status s = write_file_atomically(index_file(folder), index.dump()); !s) return s;
  for (const auto& [map, key] : keys) {
    nlohmann::json files = nlohmann::json::array();
    for (std::size_t t = 0; t < baked.size(); ++t) {
      // The map by value: clang 14 (the fuzz build) refuses a lambda naming a structured binding.
      const auto found = std::find_if(baked[t].maps.begin(), baked[t].maps.end(), [kept = map](const MapImage& m) { return m.map == kept; });
      if (found == baked[t].maps.end()) return Error{"", "internal: a kept map is not in the bake"};
      const std::string_view bytes(reinterpret_cast<const char*>(found->values.data()), found->values.size() * sizeof(float));
      if (Status s = write_file_atomically(map_file(folder, map, t), bytes); !s) return s;
      files.push_back({{"hash", hex128(XXH3_128bits(bytes.data(), bytes.size()))}});
    }
    index["maps"][std::string(name_in(kMapNames, map))] = {{"key", key}, {"files", files}};
  }
  return write_file_atomically(index_file(folder), index.dump());
}

std::vector<fs::path> kept_files(const fs::path& folder, std::span<const Map> maps, std::size_t targets) {
  std::vector<fs::path> files{index_file(folder)};
  for (Map map : maps) {
    for (std::size_t t = 0; t < targets; ++t) files.push_back(map_file(folder, map, t));
  }
  return files;
}

}  // namespace matbake::bake
