// bake::Request's parameters: names, kinds, ranges, help and examples; defaults are the struct's.
#include <charconv>
#include <cmath>

#include "matbake/ao_params.hpp"
#include "matbake/bake_params.hpp"
#include "matbake/encoding_params.hpp"

namespace matbake::bake {
namespace {

using params::Param;
using params::Spec;
using params::Value;
constexpr double kUnbounded = HUGE_VAL;

// "normal,height": maps, each once, in the order given ("none": no map), of those `allowed` takes.
std::optional<std::string> read_maps(const std::string& text, bool (*allowed)(Map), const std::string& which, std::vector<Map>& out) {
  std::vector<Map> chosen;
  for (std::size_t start = 0; text != "none" && start <= text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const auto map = value_in(kMapNames, std::string_view(text).substr(start, comma - start));
    if (!map || !allowed(*map)) return which + ", comma-separated, or none";
    if (std::find(chosen.begin(), chosen.end(), *map) != chosen.end()) return "each map once";
    chosen.push_back(*map);
    start = comma + 1;
  }
  out = std::move(chosen);
  return std::nullopt;
}
std::string maps_text(const std::vector<Map>& maps) {
  std::string text;
  for (Map m : maps) {
    if (!text.empty()) text += ',';  // appended: GCC 12 -O3 misreads `"," + std::string` (report_page.cpp)
    text += name_in(kMapNames, m);
  }
  return text.empty() ? "none" : text;
}
bool any_map(Map) { return true; }

// "bolt=0.4,plate=0.02" (a manifest's table { bolt = 0.4, plate = 0.02 }, params/toml_value.cpp):
// each part once, its distance a number 0 or more.
using ByPart = std::map<std::string, double, std::less<>>;
std::optional<std::string> read_by_part(const std::string& text, ByPart& out) {
  ByPart parts;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string_view item = std::string_view(text).substr(start, comma - start);
    const std::size_t equals = item.find('=');
    double distance = 0;
    const std::string_view number = equals == std::string_view::npos ? "" : item.substr(equals + 1);
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), distance);
    if (equals == 0 || number.empty() || error != std::errc() || end != number.data() + number.size() || !(distance >= 0) ||
        !std::isfinite(distance)) {
      return "part=distance pairs, comma-separated (bolt=0.4,plate=0.02), each distance 0 or more";
    }
    if (!parts.emplace(std::string(item.substr(0, equals)), distance).second) return "each part once";
    start = comma + 1;
  }
  out = std::move(parts);
  return std::nullopt;
}
std::string by_part_text(const ByPart& parts) {
  std::string text;
  for (const auto& [part, distance] : parts) {
    char number[32];
    const auto written = std::to_chars(number, number + sizeof number, distance);  // the shortest that reads back
    if (!text.empty()) text += ',';
    text += part;
    text += '=';
    text.append(number, written.ptr);
  }
  return text;
}

Param<Request> by_part(std::string name, ByPart Options::*field, std::string help) {
  Spec spec{.name = std::move(name), .kind = params::Kind::text, .help = std::move(help), .example = "bolt=0.4,plate=0.02",
            .needs = {{"match", "by_name"}}};
  return {std::move(spec), [field](Request& r, const Value& v) { return read_by_part(std::get<std::string>(v), r.bake.*field); },
          [field](const Request& r) { return nlohmann::json(by_part_text(r.bake.*field)); }};
}

Param<Request> maps() {
  Spec spec{.name = "maps",
            .kind = params::Kind::text,
            .help = "The texture maps to bake, comma-separated (or none): " + names_in(kMapNames),
            .example = "normal,height"};
  return {std::move(spec),
          [](Request& r, const Value& v) { return read_maps(std::get<std::string>(v), any_map, "maps among " + names_in(kMapNames), r.bake.maps); },
          [](const Request& r) { return nlohmann::json(maps_text(r.bake.maps)); }};
}

Param<Request> vertex_maps() {
  Spec spec{.name = "vertex_maps",
            .kind = params::Kind::text,
            .help = "Maps baked per low-poly vertex into attributes (_AO, _THICKNESS, _CURVATURE, _HEIGHT), "
                    "comma-separated: ao, thickness, curvature, height",
            .example = "ao,curvature"};
  return {std::move(spec),
          [](Request& r, const Value& v) {
            return read_maps(std::get<std::string>(v), per_vertex, "vertex maps among ao, thickness, curvature, height", r.bake.vertex_maps);
          },
          [](const Request& r) { return nlohmann::json(maps_text(r.bake.vertex_maps)); }};
}

Param<Request> size() {
  Spec spec{.name = "size", .kind = params::Kind::integer_or_text, .help = "The maps' size (1024, or WxH)", .example = "512x256"};
  return {std::move(spec),
          [](Request& r, const Value& v) -> std::optional<std::string> {
            std::optional<std::pair<int, int>> size;
            if (const auto* side = std::get_if<std::int64_t>(&v)) {
              if (*side >= 1 && *side <= ao::kMaxTextureSide) size = std::pair{int(*side), int(*side)};
            } else {
              size = image::size_from_text(std::get<std::string>(v));
            }
            if (!size) return "a size such as 1024 or 2048x1024";
            r.texture.width = size->first, r.texture.height = size->second;
            return std::nullopt;
          },
          [](const Request& r) { return nlohmann::json(std::to_string(r.texture.width) + "x" + std::to_string(r.texture.height)); }};
}

params::Group<Request> make_group() {
  params::Group<Request> g;
  g.params = {
      maps(),
      vertex_maps(),
      ao::into_attribute<Request>(Spec{.name = "vertex_ao_into",
                                       .help = "Per-vertex AO as _AO (a float attribute) or COLOR_0 (multiplies the "
                                               "base colour in any viewer)",
                                       .example = "COLOR_0",
                                       .needs = {{"vertex_maps", "ao", true}}},
                                  &Request::vertex_ao_into),
      ao::into_existing<Request>(Spec{.name = "vertex_existing_colors",
                                      .help = "With COLOR_0, a primitive's own COLOR_0: multiply (kept, times AO; alpha "
                                              "kept) or replace",
                                      .example = "replace"},
                                 "vertex_ao_into", &Request::vertex_ao_into),
      params::number<Request>(Spec{.name = "front",
                                   .help = "How far outside the low-poly the rays start: a fraction of its bounding-box "
                                           "diagonal (scene units with absolute_cage)",
                                   .min = 0, .max = kUnbounded, .example = "0.02"},
                              [](auto& r) -> auto& { return r.bake.front; }),
      params::number<Request>(Spec{.name = "back",
                                   .help = "How far inside the low-poly the rays reach, as front",
                                   .min = 0, .max = kUnbounded, .example = "0.02"},
                              [](auto& r) -> auto& { return r.bake.back; }),
      by_part("front_by_part", &Options::front_by_part,
              "Parts' own front, by name as match by_name keys them (part=distance, comma-separated; a manifest "
              "table { part = distance })"),
      by_part("back_by_part", &Options::back_by_part, "Parts' own back, as front_by_part"),
      params::flag<Request>(Spec{.name = "absolute_cage", .help = "front and back in scene units", .example = "true"},
                            [](auto& r) -> auto& { return r.bake.absolute_distances; }),
      params::flag<Request>(Spec{.name = "average_normals",
                                 .help = "Without a cage mesh, rays start front out along normals averaged where split "
                                         "vertices meet (hard edges: no gap or doubled detail along them); off: along "
                                         "each face's own interpolated normal",
                                 .example = "false"},
                            [](auto& r) -> auto& { return r.bake.average_normals; }),
      params::flag<Request>(Spec{.name = "high_normal_maps",
                                 .help = "The normal map takes the high-poly's own normal maps at each hit (in its "
                                         "tangent basis) over its vertex normals",
                                 .example = "true",
                                 .needs = {{"maps", "normal", true}}},
                            [](auto& r) -> auto& { return r.bake.high_normal_maps; }),
      params::choice<Request>(Spec{.name = "green",
                                   .help = "The normal map's green: opengl (glTF's: up the texture) or directx (refused "
                                           "with the normal map: a glTF viewer shades it inverted; bent_normal follows it)",
                                   .example = "directx",
                                   .needs = {{"maps", "normal,bent_normal", true}}},
                              [](auto& r) -> auto& { return r.bake.green; }, kGreenNames),
      params::choice<Request>(Spec{.name = "id_by",
                                   .help = "What the id map colours: the hit's material or its glTF primitive",
                                   .example = "primitive",
                                   .needs = {{"maps", "id", true}}},
                              [](auto& r) -> auto& { return r.bake.id_by; }, kIdSourceNames),
      params::choice<Request>(Spec{.name = "match",
                                   .help = "Which high-poly parts a low-poly part's rays meet: always (every one) or "
                                           "by_name (NAME_low... meets NAME_high...: parts close together bake as if "
                                           "exploded)",
                                   .example = "by_name"},
                              [](auto& r) -> auto& { return r.bake.match; }, kMatchNames),
      params::choice<Request>(Spec{.name = "occluders",
                                   .help = "With match by_name, what a hit's AO, bent-normal and thickness rays meet: "
                                           "its own part (matched) or every part (all: contact shadows)",
                                   .example = "all"},
                              [](auto& r) -> auto& { return r.bake.occluders; }, kOccluderNames),
      size(),
      params::integer<Request>(Spec{.name = "padding",
                                    .help = "Texels around the UV islands that take the nearest island texel's value "
                                            "(-1: 16 at 1024, scaled)",
                                    .min = -1, .max = ao::kMaxTextureSide, .example = "2"},
                               [](auto& r) -> auto& { return r.texture.padding; }),
      params::integer<Request>(Spec{.name = "texel_samples",
                                    .help = "Rays per texel, stratified over its footprint (anti-aliasing)",
                                    .min = 1, .max = 1024, .example = "16"},
                               [](auto& r) -> auto& { return r.texture.texel_samples; }),
      params::flag<Request>(Spec{.name = "per_instance",
                                 .help = "A mesh placed by several nodes: each placement its own mesh and material copy "
                                         "and its own maps (default: averaged)",
                                 .example = "true"},
                            [](auto& r) -> auto& { return r.per_instance; }),
      params::number<Request>(Spec{.name = "max_misses",
                                   .help = "The share of a material's rays that may miss the high-poly before the bake "
                                           "fails, naming the likely cause (units, placement, the cage); below it, "
                                           "misses are a warning",
                                   .min = 0, .max = 1, .example = "0.05"},
                              [](auto& r) -> auto& { return r.max_misses; }),
      params::png_bits<Request>(Spec{.name = "bits",
                                     .help = "Bits of every PNG the bake writes: 8 or 16 (the normal map's 16-bit step is "
                                             "0.0017°)",
                                     .example = "16"},
                                [](auto& r) -> auto& { return r.bits; }),
      params::choice<Request>(Spec{.name = "map_format",
                                   .help = "The maps written beside the glTF (all but normal, ao and transfer): exr (float) "
                                           "or png (bits deep, values mapped onto 0-1 as reported)",
                                   .example = "png"},
                              [](auto& r) -> auto& { return r.map_format; }, kMapFormatNames),
      params::flag<Request>(Spec{.name = "udim",
                                 .help = "Every UDIM tile the UVs touch baked into maps of its own "
                                         "(<stem>_<material>_<map>.<tile>); in the glTF, one material per tile",
                                 .example = "true"},
                            [](auto& r) -> auto& { return r.udim; }),
      params::integer<Request>(Spec{.name = "seed", .help = "Scrambling seed of the texel positions",
                                    .min = 0, .max = 9007199254740992.0, .example = "3"},
                               [](auto& r) -> auto& { return r.bake.seed; }),
  };
  g.check = [](const Request& r) -> Status { return check(r); };
  return g;
}

}  // namespace

const params::Group<Request>& request_params() {
  static const params::Group<Request> group = make_group();
  return group;
}

const params::Tree<FileOptions>& request_tree() {
  static const params::Tree<FileOptions> tree{
      params::branch<FileOptions>(image::encoding_params(), "", "", [](auto& o) -> auto& { return o.encoding; }),
      params::branch<FileOptions>(request_params(), "", "", [](auto& o) -> auto& { return o.request; }),
      params::branch<FileOptions>(ao::estimator_params(), "ao", "ao-", [](auto& o) -> auto& { return o.request.occlusion; }),
  };
  return tree;
}

}  // namespace matbake::bake
