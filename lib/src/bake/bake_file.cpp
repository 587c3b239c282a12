// `matbake bake`: the low-poly document read once, its scene and the high-poly's, the maps baked per
// material, written into the document (normalTexture, TANGENT) and beside it (float maps).
#include <cctype>
#include <chrono>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "../gltf/tangents.hpp"
#include "../gltf/texture_files.hpp"
#include "../gltf/placements.hpp"
#include "../gltf/prune.hpp"
#include "../gltf/texture_transform.hpp"
#include "../gltf/vertex_occlusion.hpp"
#include "../scene/from_document.hpp"
#include "frames.hpp"
#include "map_cache.hpp"
#include "udim.hpp"
#include "matbake/bake_file.hpp"
#include "matbake/join.hpp"
#include "matbake/output_check.hpp"

namespace matbake::bake {
namespace fs = std::filesystem;
namespace {

using gltf::Json;

struct Targets {
  std::vector<ao::TextureTarget> targets;
  std::vector<int> materials;  // each target's
  std::vector<int> nodes;      // with per_instance, the node placing each target's instances; else -1
  std::vector<int> tiles;      // with Request::udim, each target's UDIM tile; else 0
  std::vector<std::string> notes;
};

// The UV set a material's normal map is read through: its normalTexture's, else 0.
int normal_texcoord(const Json& material) {
  if (!material.contains("normalTexture") || !material["normalTexture"].is_object()) return 0;
  return gltf::integer_in<int>(material["normalTexture"], "texCoord", 0, 0);
}

std::size_t triangle_count(const scene::Scene& scene) {
  std::size_t n = 0;
  for (const scene::Instance& inst : scene.instances) n += inst.triangles.size();
  return n;
}

// Why no material of the low-poly can take maps: none has a material, the two files look swapped
// (the "low-poly" denser than the high-poly: a sculpt seldom has UVs), or none has its UV set.
std::string no_target_reason(const scene::Scene& low, bool no_material, const fs::path& high) {
  const std::size_t low_triangles = triangle_count(low);
  if (auto dense = scene::load_scene(high); dense && low_triangles > triangle_count(*dense)) {
    return std::string(no_material ? "the low-poly has no material" : "the low-poly's materials lack their UV sets") + ", and it has " +
           std::to_string(low_triangles) + " triangles, more than the high-poly's " + std::to_string(triangle_count(*dense)) +
           ": are the two swapped? (the low-poly takes the maps, the high-poly gives them)";
  }
  if (no_material) return "no primitive of the low-poly has a material, and baked maps go into one: give its primitives a material";
  return "no material of the low-poly can take baked maps: each needs its UV set (TEXCOORD_n of its normalTexture, else "
         "TEXCOORD_0) on all its primitives; unwrap the low-poly";
}

// One target per material the low-poly's instances use (per placing node too with `per_instance`),
// when every one of them has its UV set; `high` is read only to say why there is none.
Result<Targets> material_targets(const gltf::Document& doc, const scene::Scene& low, bool per_instance, const fs::path& high) {
  const Json& materials = gltf::array_in(doc.json, "materials");
  std::map<std::pair<int, int>, std::vector<std::size_t>> by_material;  // (material, node or -1) → instances
  Targets out;
  for (std::size_t k = 0; k < low.instances.size(); ++k) {
    const int m = low.instances[k].material;
    if (m >= 0 && std::size_t(m) < materials.size()) by_material[{m, per_instance ? low.instances[k].node : -1}].push_back(k);
  }
  if (std::size_t without = low.instances.size() - [&] {
        std::size_t n = 0;
        for (const auto& [m, k] : by_material) n += k.size();
        return n;
      }()) {
    out.notes.push_back(std::to_string(without) + " placed primitives have no material: nothing baked onto them");
  }
  for (const auto& [key, instances] : by_material) {
    const auto [m, node] = key;
    const Json& material = materials[std::size_t(m)];
    ao::TextureTarget target{instances, normal_texcoord(material)};
    target.name = "material " + std::to_string(m) + " '" + gltf::name_in(material, "") + "'" +
                  (node >= 0 ? " on node " + std::to_string(node) : "");
    const auto lacking = std::find_if(instances.begin(), instances.end(), [&](std::size_t k) {
      const auto& uv = low.instances[k].texcoords;
      return std::size_t(target.texcoord) >= uv.size() || uv[std::size_t(target.texcoord)].empty();
    });
    if (lacking != instances.end()) {
      out.notes.push_back(target.name + " is used by mesh " + std::to_string(low.instances[*lacking].mesh) + " primitive " +
                          std::to_string(low.instances[*lacking].primitive) + ", which has no TEXCOORD_" +
                          std::to_string(target.texcoord) + ": not baked");
      continue;
    }
    std::set<std::pair<int, int>> placed;
    for (std::size_t k : instances) {
      if (!placed.insert({low.instances[k].mesh, low.instances[k].primitive}).second) {
        out.notes.push_back(target.name + ": mesh " + std::to_string(low.instances[k].mesh) +
                            " is placed by several nodes; its texels hold the mean of the placements");
        break;
      }
    }
    out.materials.push_back(m);
    out.nodes.push_back(node);
    out.tiles.push_back(0);
    out.targets.push_back(std::move(target));
  }
  if (out.targets.empty()) return Error{doc.file, no_target_reason(low, by_material.empty(), high)};
  return out;
}

// The material's texture a map becomes (`key` of the material, or of its `parent` object), and how
// its colour channels are encoded; none: a float file beside the output.
struct Slot {
  const char* parent;
  const char* key;
  color::Transfer colour;
};
std::optional<Slot> material_slot(Map map) {
  switch (map) {
    case Map::normal: return Slot{nullptr, "normalTexture", color::Transfer::linear};
    case Map::ao: return Slot{nullptr, "occlusionTexture", color::Transfer::linear};
    case Map::transfer: return Slot{"pbrMetallicRoughness", "baseColorTexture", color::Transfer::srgb};
    default: return std::nullopt;
  }
}

// A material's textureInfo `info` (at JSON pointer `where`) as the bake samples it: decoded with
// `colour`, with its UV set, transform and sampler's wrap modes.
Result<MaterialTexture> material_texture(const gltf::Document& doc, const gltf::ImageCache& cache, const Json& info,
                                         color::Transfer colour, const std::string& where) {
  const int index = gltf::integer_in<int>(info, "index", -1, -1);
  auto decoded = cache.decode(index, colour);
  if (!decoded) return decoded.error();
  MaterialTexture out;
  out.image = std::move(*decoded);
  auto transform = gltf::uv_transform_of(info, doc.file, where);
  if (!transform) return transform.error();
  out.texcoord = transform->texcoord >= 0 ? transform->texcoord : gltf::integer_in<int>(info, "texCoord", 0, 0);
  if (!transform->identity()) out.transform = [t = *transform](glm::dvec2 uv) { return t.apply(uv); };
  const int sampler = gltf::integer_in<int>(doc.json["textures"][std::size_t(index)], "sampler", -1, -1);
  if (sampler >= 0) {
    const Json& s = doc.json["samplers"][std::size_t(sampler)];
    out.wrap_s = gltf::wrap_of(s, "wrapS"), out.wrap_t = gltf::wrap_of(s, "wrapT");
  }
  return out;
}

// Every primitive of material `m` has the UV set `texcoord` its normal map reads: else that map
// would be left out of the bake without a word. The error names the file and the primitive.
Status check_normal_uvs(const gltf::Document& doc, int m, int texcoord) {
  const Json& meshes = doc.json.value("meshes", Json::array());
  const std::string set = "TEXCOORD_" + std::to_string(texcoord);
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const Json& primitives = meshes[i].is_object() ? meshes[i].value("primitives", Json::array()) : Json::array();
    for (std::size_t j = 0; j < primitives.size(); ++j) {
      const Json& p = primitives[j];
      if (!p.is_object() || p.value("material", Json(-1)) != Json(m)) continue;
      if (p.contains("attributes") && p["attributes"].is_object() && p["attributes"].contains(set)) continue;
      return Error{doc.file, "/meshes/" + std::to_string(i) + "/primitives/" + std::to_string(j) + ": its material " +
                                          std::to_string(m) + "'s normal map reads " + set + ", which it lacks: " +
                                          mention("high_normal_maps") + " cannot apply it"};
    }
  }
  return success();
}

// What the high-poly's materials give: base colours (factors, textures decoded to linear) when
// `colours`, normal maps (codes as stored, with their scale) when `normals`.
Result<HighMaterials> high_materials(const fs::path& high, const image::Encoding& encoding, bool colours, bool normals) {
  auto doc = gltf::read_document(high);
  if (!doc) return doc.error();
  gltf::ImageCache cache(*doc, encoding, gltf::MadeFormat::png);
  HighMaterials out;
  const Json& materials = doc->json.value("materials", Json::array());
  for (std::size_t m = 0; m < materials.size(); ++m) {
    const std::string where = "/materials/" + std::to_string(m);
    if (normals) {
      std::optional<NormalTexture>& normal = out.normals.emplace_back();
      if (materials[m].contains("normalTexture") && materials[m]["normalTexture"].is_object()) {
        const Json& info = materials[m]["normalTexture"];
        auto texture = material_texture(*doc, cache, info, color::Transfer::linear, where + "/normalTexture");
        if (!texture) return texture.error();
        const Json scale = info.value("scale", Json(1.0));  // absent (its default) in most files
        normal = NormalTexture{std::move(*texture), scale.is_number() ? scale.get<double>() : 1.0};
      }
    }
    if (normals && out.normals.back()) {
      if (Status s = check_normal_uvs(*doc, int(m), out.normals.back()->texture.texcoord); !s) return s.error();
    }
    if (!colours) continue;
    BaseColor& color = out.base_colors.emplace_back();
    const Json pbr = materials[m].value("pbrMetallicRoughness", Json::object());
    const Json factor = pbr.value("baseColorFactor", Json::array({1, 1, 1, 1}));
    if (factor.is_array() && factor.size() == 4) {
      for (int k = 0; k < 4; ++k) color.factor[k] = factor[std::size_t(k)].is_number() ? factor[std::size_t(k)].get<float>() : 1.0f;
    }
    if (!pbr.contains("baseColorTexture") || !pbr["baseColorTexture"].is_object()) continue;
    auto texture = material_texture(*doc, cache, pbr["baseColorTexture"], color::Transfer::srgb, where + "/pbrMetallicRoughness/baseColorTexture");
    if (!texture) return texture.error();
    color.texture = std::move(*texture);
  }
  return out;
}

// What a map's files are named: <stem>_<material>_<map>, and .<tile> with a UDIM tile.
std::string map_file_stem(const fs::path& output, const std::string& material_name, Map map, int tile) {
  return output.stem().string() + "_" + material_name + "_" + std::string(matbake::name_in(kMapNames, map)) +
         (tile ? "." + std::to_string(tile) : "");
}

// A map written beside the output (not one of the material's textures): EXR or PNG.
fs::path beside_file(const fs::path& output, const std::string& material_name, Map map, int tile, MapFormat format) {
  return output.parent_path() / (map_file_stem(output, material_name, map, tile) + (format == MapFormat::png ? ".png" : ".exr"));
}

image::SampleType png_type(const Request& request) { return request.bits == 16 ? image::SampleType::u16 : image::SampleType::u8; }

// The bytes of a map beside the output: float EXR, or a PNG of its values mapped onto 0–1 by
// `png_range` (its map_range, or its material's tiles'), which `range` is set to.
Result<std::string> encode_beside(image::Image img, const fs::path& file, const FileOptions& options,
                                  std::pair<double, double> png_range, std::optional<std::pair<double, double>>& range) {
  image::WriteOptions write;
  write.png_level = options.encoding.png_level;
  if (options.request.map_format == MapFormat::exr) {
    write.type = image::SampleType::f32;
    range.reset();
    return image::encode_image(img, file, write);
  }
  range = png_range;
  const double scale = 1.0 / (range->second - range->first);
  for (float& v : img.pixels) v = float(std::clamp((double(v) - range->first) * scale, 0.0, 1.0));
  write.type = png_type(options.request);
  return image::encode_image(img, file, write);
}

// The triangles of each (mesh, primitive) whose vertices TANGENT renumbered, as written.
using Renumbered = std::map<std::pair<int, int>, std::vector<std::uint32_t>>;

// TANGENT (and NORMAL where missing) on each baked primitive, once per mesh primitive.
Status write_tangents(gltf::Document& doc, const scene::Scene& low, const Targets& targets, FileReport& report, Renumbered& written) {
  std::set<std::pair<int, int>> done;
  for (const ao::TextureTarget& target : targets.targets) {
    for (std::size_t k : target.instances) {
      const scene::Instance& inst = low.instances[k];
      // The node's mesh as the document has it now: a placement given its own (per_instance) too.
      const int mesh = doc.json["nodes"][std::size_t(inst.node)]["mesh"].get<int>();
      if (!inst.object.tangents.empty() || !done.insert({mesh, inst.primitive}).second) continue;
      auto tangents = corner_tangents(inst, target.texcoord);
      if (!tangents) return tangents.error();
      gltf::PrimitiveTangents p{mesh, inst.primitive, {}, {}, {}};
      const std::vector<glm::vec3> normals = corner_normals(inst);
      for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
        p.triangles.push_back(file_triangle(inst, t));
        for (std::size_t c = 0; c < 3; ++c) {
          p.tangents.push_back((*tangents)[3 * t + file_corner(inst, c)]);
          p.normals.push_back(normals[3 * t + file_corner(inst, c)]);
        }
      }
      auto added = gltf::add_tangents(doc, p);
      if (!added) return added.error();
      ++report.tangent_primitives;
      report.split_vertices += added->vertices;
      if (added->vertices) written[{mesh, inst.primitive}] = std::move(added->triangles);
    }
  }
  return success();
}

// Each map's range (map_range) over the texture targets of one material, as PNGs beside the
// output map it (a UDIM set is read with one scale): per target, per map.
std::vector<std::vector<std::pair<double, double>>> material_ranges(const Targets& targets, const Bake& baked) {
  std::map<std::pair<int, int>, std::vector<std::pair<double, double>>> of;  // (material, node) → per map
  for (std::size_t t = 0; t < baked.textures.size(); ++t) {
    auto [it, first] = of.try_emplace({targets.materials[t], targets.nodes[t]});
    for (std::size_t i = 0; i < baked.textures[t].maps.size(); ++i) {
      const auto [lo, hi] = map_range(baked.textures[t].maps[i]);
      if (first) it->second.emplace_back(lo, hi);
      else it->second[i] = {std::min(it->second[i].first, lo), std::max(it->second[i].second, hi)};
    }
  }
  std::vector<std::vector<std::pair<double, double>>> out;
  for (std::size_t t = 0; t < baked.textures.size(); ++t) out.push_back(of.at({targets.materials[t], targets.nodes[t]}));
  return out;
}

// The texture target `t`'s maps into material `m` of the document and beside the output, their
// files named for `file_name` (its material's, or with a UDIM tile the material copied's), PNGs
// beside it mapped by `ranges` (per map).
Result<TextureReport> write_maps(gltf::Document& doc, const gltf::ImageCache& cache, const FileOptions& options,
                                 const Targets& targets, std::size_t t, int m, const std::string& file_name,
                                 const std::vector<std::pair<double, double>>& ranges, TextureBake& baked) {
  Json& material = doc.json["materials"][std::size_t(m)];
  TextureReport report;
  report.material = m;
  report.name = gltf::name_in(material, "");
  report.tile = targets.tiles[t];
  report.width = baked.width, report.height = baked.height, report.texcoord = targets.targets[t].texcoord;
  report.texels = baked.texels, report.samples = baked.samples, report.misses = baked.misses;
  report.missed_texels = baked.missed_texels, report.padded = baked.padded;
  report.from_inside = baked.from_inside, report.overlapped = baked.overlapped, report.outside_tile = baked.outside_tile;
  report.faced_away = baked.faced_away, report.skipped_triangles = baked.degenerate_uv + baked.too_large;
  report.height_min = baked.height_min, report.height_max = baked.height_max;
  report.occlusion_rays = baked.occlusion_rays;
  for (std::size_t i = 0; i < baked.maps.size(); ++i) {
    MapImage& map = baked.maps[i];
    image::Image img = gltf::blank(baked.width, baked.height, map.channels);
    img.pixels = map.values;
    const std::optional<Slot> slot = material_slot(map.map);
    std::optional<std::pair<double, double>>& range = report.ranges.emplace_back(std::pair(0.0, 1.0));
    if (!slot) {
      // Written with the document, after every check of its files.
      const fs::path file = beside_file(options.output, file_name, map.map, report.tile, options.request.map_format);
      auto bytes = encode_beside(std::move(img), file, options, ranges[i], range);
      if (!bytes) return bytes.error();
      doc.beside[file.filename().string()] = std::move(*bytes);
      report.files.push_back(file.string());
      continue;
    }
    Json& holder = slot->parent ? material[slot->parent] : material;
    int sampler_from = -1;
    Json info = Json::object();
    if (holder.contains(slot->key) && holder[slot->key].is_object()) {
      // A UDIM tile's image is sampled at the file's own UVs, past 0–1: glTF's default sampler
      // repeats it; the old texture's might clamp.
      if (!report.tile) sampler_from = gltf::integer_in<int>(holder[slot->key], "index", -1, -1);
      // An occlusion's strength is the artist's; a normal map's scale was for the old map.
      if (map.map == Map::ao && holder[slot->key].contains("strength")) info["strength"] = holder[slot->key]["strength"];
      report.existing += std::string(report.existing.empty() ? "" : ", ") + std::string(matbake::name_in(kMapNames, map.map)) + " replaced";
    }
    const std::string name = map_file_stem(options.output, file_name, map.map, report.tile);
    auto made = cache.add_texture(doc, img, slot->colour, name, sampler_from, png_type(options.request));
    if (!made) return made.error();
    info["index"] = made->index;  // no transform: the bake is over raw UVs
    if (report.texcoord != 0) info["texCoord"] = report.texcoord;
    holder[slot->key] = std::move(info);
    if (map.map == Map::transfer) holder["baseColorFactor"] = {1.0, 1.0, 1.0, 1.0};  // the texture holds it
    report.files.push_back(made->uri);
  }
  return report;
}

// The vertex maps into the low-poly's primitives (ao where Request::vertex_ao_into says, the others
// as _THICKNESS, _CURVATURE, _HEIGHT): per mesh primitive the mean over the nodes placing it (as a
// texel holds the mean of the placements), written through the first of them; with per_instance,
// each placement's own (its mesh copied where another node placed it first).
void write_vertex_maps(gltf::Document& doc, const scene::Scene& low, const VertexBake& baked, ao::Into ao_into, bool per_instance,
                       FileReport& report) {
  std::map<std::tuple<int, int, int>, std::vector<std::size_t>> placements;  // (mesh, primitive, node or -1) → instances
  for (std::size_t k = 0; k < low.instances.size(); ++k) {
    const scene::Instance& inst = low.instances[k];
    placements[{inst.mesh, inst.primitive, per_instance ? inst.node : -1}].push_back(k);
  }
  for (const auto& [primitive, instances] : placements) {
    if (instances.size() > 1) {
      report.notes.push_back("mesh " + std::to_string(std::get<0>(primitive)) +
                             " is placed by several nodes; its vertices hold the mean of the placements");
    }
  }
  for (std::size_t m = 0; m < baked.maps.size(); ++m) {
    std::vector<std::vector<float>> means;
    std::vector<gltf::PlacedValues> placed;
    means.reserve(placements.size());
    for (const auto& [primitive, instances] : placements) {
      std::vector<float>& mean = means.emplace_back(baked.values[m][instances[0]].size(), 0.0f);
      for (std::size_t k : instances) {
        for (std::size_t v = 0; v < mean.size(); ++v) mean[v] += baked.values[m][k][v] / float(instances.size());
      }
      const scene::Instance& first = low.instances[instances[0]];
      placed.push_back({first.node, first.primitive, mean, first.colors, first.colors_have_alpha});
    }
    std::string name(matbake::name_in(kMapNames, baked.maps[m]));
    if (baked.maps[m] == Map::ao) {
      gltf::add_vertex_occlusion(doc, placed, ao_into);
      report.vertices.attributes.emplace_back(ao::into_attribute_name(ao_into));
      continue;
    }
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::toupper(c)); });
    gltf::add_vertex_scalars(doc, placed, "_" + name);
    report.vertices.attributes.push_back("_" + name);
  }
  report.vertices.vertices = baked.vertices, report.vertices.misses = baked.misses;
  report.vertices.occlusion_rays = baked.occlusion_rays;
}

// The files a glTF is read from (itself, its buffers and images); none when its JSON cannot be
// read (its loading then says why).
std::vector<fs::path> files_of(const fs::path& gltf) {
  const auto json = gltf::read_json(gltf);
  return json ? gltf::source_files(gltf, *json) : std::vector<fs::path>{gltf};
}

// The bake of `maps` alone: the high-poly loaded (with its base colours only for transfer), traced.
Result<Bake> trace_maps(const scene::Scene& low, const Targets& targets, const FileOptions& options, const std::vector<Map>& maps) {
  const bool transfer = std::find(maps.begin(), maps.end(), Map::transfer) != maps.end();
  const bool detail = options.request.bake.high_normal_maps && std::find(maps.begin(), maps.end(), Map::normal) != maps.end();
  auto high = scene::load_scene(options.high, {.texcoords = transfer || detail, .object_space = detail});
  if (!high) return high.error();
  HighMaterials materials;
  if (transfer || detail) {
    auto read = high_materials(options.high, options.encoding, transfer, detail);
    if (!read) return read.error();
    materials = std::move(*read);
  }
  std::optional<scene::Scene> cage;
  if (!options.cage.empty()) {
    auto loaded = scene::load_scene(options.cage);
    if (!loaded) return loaded.error();
    if (const std::string why = cage_mismatch(low, *loaded); !why.empty()) return Error{options.cage.string(), "cannot be the low-poly's cage: it " + why};
    cage = std::move(*loaded);
  }
  Options asked = options.request.bake;
  asked.maps = maps;
  return bake(low, *high, targets.targets, options.request.texture, asked, options.request.occlusion.options, materials,
              cage ? &*cage : nullptr);
}

// Every asked map, each read back from options.keep when kept there under its key (map_cache.hpp),
// the others traced and kept; `reused` names those read back.
Result<Bake> bake_or_reuse(const scene::Scene& low, const Targets& targets, const FileOptions& options, const std::string& inputs,
                           std::vector<std::string>& reused) {
  const std::vector<Map>& maps = options.request.bake.maps;
  const ao::TextureOptions& texture = options.request.texture;
  std::string targets_text;
  for (std::size_t t = 0; t < targets.targets.size(); ++t) {
    targets_text += std::to_string(targets.materials[t]) + "@" + std::to_string(targets.nodes[t]) + ":" +
                    std::to_string(targets.targets[t].texcoord) + (targets.tiles[t] ? "#" + std::to_string(targets.tiles[t]) : "") + " ";
  }
  const bool keeping = !options.keep.empty() && !inputs.empty();
  const std::string trace_key = keeping ? map_key(inputs, std::nullopt, options.request, targets_text) : "";
  std::vector<std::optional<KeptMap>> kept(maps.size());
  std::vector<Map> to_trace;
  for (std::size_t i = 0; i < maps.size(); ++i) {
    if (keeping) kept[i] = load_map(options.keep, maps[i], map_key(inputs, maps[i], options.request, targets_text),
                                    targets.targets.size(), texture.width, texture.height);
    if (!kept[i]) to_trace.push_back(maps[i]);
  }
  std::optional<Bake> counts;
  if (to_trace.empty() && !maps.empty()) {
    counts = load_trace(options.keep, trace_key, targets.targets.size());
    if (!counts) to_trace = maps, kept.assign(maps.size(), std::nullopt);  // kept maps without their trace's counts
  }
  Bake out;
  // The vertex maps are traced every time: one ray a vertex, not worth a kept file.
  if (!to_trace.empty() || !options.request.bake.vertex_maps.empty()) {
    auto traced = trace_maps(low, targets, options, to_trace);
    if (!traced) return traced.error();
    if (keeping && !to_trace.empty()) {
      std::vector<std::pair<Map, std::string>> keys;
      for (Map m : to_trace) keys.emplace_back(m, map_key(inputs, m, options.request, targets_text));
      if (Status s = store_maps(options.keep, *traced, trace_key, keys); !s) return s.error();
    }
    if (counts) traced->textures = std::move(counts->textures), traced->boxes = counts->boxes;  // only the vertices traced
    out = std::move(*traced);
  } else {
    out.textures = std::move(counts->textures), out.boxes = counts->boxes;
    std::optional<scene::Scene> cage;  // as the kept maps were traced (the same content: in their key)
    if (!options.cage.empty()) {
      auto loaded = scene::load_scene(options.cage);
      if (!loaded) return loaded.error();
      cage = std::move(*loaded);
    }
    std::tie(out.front, out.back) = cage_distances(low, options.request.bake, cage ? &*cage : nullptr);
  }
  for (std::size_t t = 0; t < out.textures.size(); ++t) {
    TextureBake& texture_bake = out.textures[t];
    texture_bake.width = texture.width, texture_bake.height = texture.height;
    std::vector<MapImage> in_order;
    for (std::size_t i = 0; i < maps.size(); ++i) {
      if (kept[i]) {
        in_order.push_back(std::move(kept[i]->images[t]));
        continue;
      }
      const auto traced = std::find_if(texture_bake.maps.begin(), texture_bake.maps.end(), [&](const MapImage& m) { return m.map == maps[i]; });
      in_order.push_back(std::move(*traced));
    }
    texture_bake.maps = std::move(in_order);
  }
  for (std::size_t i = 0; i < maps.size(); ++i) {
    if (kept[i]) reused.emplace_back(matbake::name_in(kMapNames, maps[i]));
  }
  return out;
}

// 'a', 'b': names from a file, quoted and escaped (appended: GCC 12 -O3 misreads `"'" + std::string`).
std::string quoted(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    if (!text.empty()) text += ", ";
    text += '\'';
    text += escape_control(name);
    text += '\'';
  }
  return text;
}

std::string percent(std::size_t part, std::size_t whole) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g%%", 100.0 * double(part) / double(whole));
  return text;
}

// The misses judged, per texture and for the vertices: a share above max_misses is the error naming
// the likely cause; below it, any miss is a warning, as is a ray that started inside a part.
Status judge_misses(const Bake& baked, const Targets& targets, const FileOptions& options, double diagonal, FileReport& report) {
  const double limit = options.request.max_misses;
  // Of all misses when parts matched by name lack partners.
  const std::string cause = baked.unmatched.empty() ? "" : "no high-poly part matches the low-poly parts " + quoted(baked.unmatched) + " by name";
  const auto judge = [&](const std::string& what, std::size_t misses, std::size_t rays, const TextureBake* texture) -> Status {
    if (misses == 0 || rays == 0) return success();
    static const TextureBake kNoTexture;  // the vertices' misses: no texture's probes (a copy of a bake's maps cost 7%)
    const std::string why = !cause.empty() ? cause : miss_cause(baked.boxes, texture ? *texture : kNoTexture, options.request.bake, diagonal,
                                                                   !options.cage.empty());
    const std::string share = percent(misses, rays) + " of the rays (" + std::to_string(misses) + " of " + std::to_string(rays) + ")";
    if (double(misses) > limit * double(rays)) {
      char limit_text[32];
      std::snprintf(limit_text, sizeof limit_text, "%g", limit + 0.0);  // + 0.0: never "-0"
      return Error{"", what + ": " + share + " missed the high-poly, more than " + mention("max_misses", limit_text) + " allows: " + why};
    }
    report.warnings.push_back(what + ": " + share + " missed the high-poly (their texels take their neighbours' values): " + why);
    return success();
  };
  for (std::size_t t = 0; t < baked.textures.size() && t < targets.targets.size(); ++t) {
    const TextureBake& texture = baked.textures[t];
    const std::string& what = targets.targets[t].name;
    if (Status s = judge(what, texture.misses, texture.samples, &texture); !s) return s;
    if (texture.texels == 0) {
      report.warnings.push_back(what + ": none of its UVs covers " + (targets.tiles[t] ? "its UDIM tile" : "the 0–1 tile") + " (" +
                                std::to_string(texture.outside_tile) +
                                " triangles outside it, " + std::to_string(texture.degenerate_uv) + " of no area or not finite, " +
                                std::to_string(texture.too_large) + " spanning too far): its maps hold only fill values");
    } else if (texture.degenerate_uv + texture.too_large) {
      report.warnings.push_back(what + ": " + std::to_string(texture.degenerate_uv + texture.too_large) +
                                " triangles were not baked: their UVs have no area, are not finite or span too far");
    }
    if (texture.from_inside) {
      report.warnings.push_back(what + ": " + percent(texture.from_inside, texture.samples) + " of the rays (" +
                                std::to_string(texture.from_inside) + ") started inside a closed high-poly part (their first "
                                "surface was a face's back) and read the surface beyond it: widen the cage (front) past "
                                "that part, or match parts by name");
    }
  }
  return judge("the vertices", baked.vertices.misses, baked.vertices.vertices, nullptr);
}

// The targets split by UDIM tile (`split`, of `targets`): each tile after a material's first takes
// a copy of its material, named "<name> (<tile>)"; `into` (each target's material) and
// `file_names` (what its files are named for) follow the targets.
void apply_tiles(gltf::Document& doc, Targets& targets, const TileTargets& split, std::vector<int>& into,
                 std::vector<std::string>& file_names) {
  Targets out;
  out.notes = targets.notes;
  out.notes.insert(out.notes.end(), split.notes.begin(), split.notes.end());
  std::vector<int> tile_into;
  std::vector<std::string> tile_names;
  for (std::size_t i = 0; i < split.targets.size(); ++i) {
    const std::size_t from = split.from[i];
    out.targets.push_back(split.targets[i]);
    out.materials.push_back(targets.materials[from]), out.nodes.push_back(targets.nodes[from]), out.tiles.push_back(split.tiles[i]);
    tile_names.push_back(file_names[from]);
    int m = into[from];
    if (i > 0 && split.from[i - 1] == from) {
      Json copy = doc.json["materials"][std::size_t(m)];
      copy["name"] = gltf::name_in(copy, "material " + std::to_string(m)) + " (" + std::to_string(split.tiles[i]) + ")";
      doc.json["materials"].push_back(std::move(copy));
      m = int(doc.json["materials"].size()) - 1;
    }
    tile_into.push_back(m);
  }
  targets = std::move(out), into = std::move(tile_into), file_names = std::move(tile_names);
}

// What of a document a bake may remove once it has written its maps: what the scene reached as
// read and no longer does (a texture the baked one replaced, its image and sampler; the accessors
// the tangents' split vertices replaced). The file's own unused objects stay, and so does every
// material and mesh (the report names them by index).
gltf::Reachable reach_before_bake(Json& json) {
  gltf::Reachable reached = gltf::reachable(json);
  std::fill(reached.materials.begin(), reached.materials.end(), false);
  std::fill(reached.meshes.begin(), reached.meshes.end(), false);
  return reached;
}

}  // namespace

Status check(const Request& request) {
  if (Status s = check(request.bake); !s) return s;
  const Options& bake = request.bake;
  if (bake.green != Green::directx || std::ranges::find(bake.maps, Map::normal) == bake.maps.end()) return success();
  return Error{"", mention("green", "directx") + ": a glTF's normalTexture is OpenGL's convention (green up the texture), and "
                   "every glTF viewer would shade this normal map inverted; bake with " + mention("green", "opengl") +
                   " (and flip green in the engine's import), or leave normal out of the maps (bent_normal, written "
                   "beside the glTF, follows green)",
               true};
}

std::pair<double, double> map_range(const MapImage& image) {
  double lo = 0, hi = 1, largest = 0;
  const auto [smallest, biggest] = std::minmax_element(image.values.begin(), image.values.end());
  for (float v : image.values) largest = std::max(largest, double(std::abs(v)));
  switch (image.map) {
    case Map::height:
    case Map::curvature: lo = -largest, hi = largest; break;
    case Map::thickness: lo = 0, hi = largest; break;
    case Map::position:
      if (smallest != image.values.end()) lo = *smallest, hi = *biggest;
      break;
    default: return {0.0, 1.0};  // encoded already
  }
  if (!(hi > lo)) lo -= 0.5, hi += 0.5;  // one value: 1 around it
  return {lo, hi};
}

Result<FileReport> bake_file(const fs::path& low_path, const FileOptions& options) {
  return guarded(low_path.string(), [&]() -> Result<FileReport> {
    if (const fs::path ext = options.output.extension(); ext != ".gltf" && ext != ".glb") {
      return Error{options.output.string(), "the output is .gltf or .glb", true};
    }
    if (Status s = check(options.request); !s) return s.error();
    const auto start = std::chrono::steady_clock::now();
    // The inputs' content before they are loaded: kept maps are keyed by what was read, at worst older.
    std::vector<fs::path> inputs = files_of(low_path);
    for (const fs::path& source : {options.high, options.cage}) {
      if (source.empty()) continue;
      const std::vector<fs::path> files = files_of(source);
      inputs.insert(inputs.end(), files.begin(), files.end());
    }
    std::string inputs_key;
    if (!options.keep.empty()) {
      if (auto hashed = inputs_hash(inputs)) inputs_key = *hashed;  // else nothing is reused; loading says why
    }
    auto doc = gltf::read_document(low_path);
    if (!doc) return doc.error();
    doc->other_inputs = inputs;  // the high-poly's and the cage's files: never written either
    const gltf::Reachable as_read = reach_before_bake(doc->json);
    auto low = scene::scene_from_document(*doc, {.texcoords = true, .object_space = true});
    if (!low) return low.error();
    // Vertex maps alone need no UVs: no texture targets.
    auto targets = options.request.bake.maps.empty() ? Result<Targets>(Targets{}) : material_targets(*doc, *low, options.request.per_instance, options.high);
    if (!targets) return targets.error();

    // Each target's material: with per_instance, a placement's own copy (and its mesh's).
    std::vector<int> into = gltf::split_placements(*doc, *low, targets->materials, targets->nodes);
    std::vector<std::string> file_names;
    for (int m : into) file_names.push_back(gltf::material_file_name(doc->json["materials"][std::size_t(m)], m));
    std::optional<TileTargets> tiles;  // with udim: a target per tile, and each tile after the first a material
    if (options.request.udim && !targets->targets.empty()) {
      auto split = udim_targets(*low, targets->targets);
      if (!split) return Error{doc->file, split.error().message};
      tiles = std::move(*split);
      apply_tiles(*doc, *targets, *tiles, into, file_names);
    }
    std::vector<NamedOutput> outputs = {{options.output, "glTF output"}};
    if (options.output.extension() == ".gltf") {
      outputs.push_back({options.output.parent_path() / (options.output.stem().string() + ".bin"), "its buffer"});
    }
    for (std::size_t t = 0; t < into.size(); ++t) {
      for (Map map : options.request.bake.maps) {
        if (material_slot(map)) continue;
        outputs.push_back({beside_file(options.output, file_names[t], map, targets->tiles[t], options.request.map_format),
                           "material " + std::to_string(into[t]) + "'s " + std::string(matbake::name_in(kMapNames, map)) + " map"});
      }
    }
    if (!options.keep.empty()) {
      for (const fs::path& f : kept_files(options.keep, options.request.bake.maps, targets->targets.size())) outputs.push_back({f, "kept map"});
    }
    if (Status s = check_outputs(outputs, inputs); !s) return s.error();

    FileReport report;
    auto baked = bake_or_reuse(*low, *targets, options, inputs_key, report.reused);
    if (!baked) {
      Error error = baked.error();
      if (error.path.empty() && !error.usage) error.path = doc->file;
      return error;
    }
    report.notes = low->notes;
    report.notes.insert(report.notes.end(), targets->notes.begin(), targets->notes.end());
    if (!baked->unmatched.empty()) {
      report.notes.push_back("no high-poly part matches these low-poly parts by name, so each of their rays misses: " +
                             quoted(baked->unmatched));
    }
    if (Status s = judge_misses(*baked, *targets, options, 2.0 * double(low->radius()), report); !s) {
      return Error{doc->file, s.error().message};
    }
    for (std::size_t t = 0; t < baked->textures.size() && t < targets->targets.size(); ++t) {
      const TextureBake& b = baked->textures[t];
      const std::string& what = targets->targets[t].name;
      if (b.outside_tile && !targets->tiles[t]) {  // a UDIM tile's: the other tiles' triangles
        report.notes.push_back(what + ": " + std::to_string(b.outside_tile) + " triangles have UVs wholly outside the 0–1 "
                               "tile (a shell moved out by whole tiles) or not finite: not baked");
      }
      if (b.overlapped) {
        report.notes.push_back(what + ": " + std::to_string(b.overlapped) + " texels are covered by several triangles "
                               "(overlapping UV islands, or a mesh placed several times): each holds their mean");
      }
    }
    report.front = baked->front, report.back = baked->back;
    report.setup_seconds = baked->setup_seconds, report.trace_seconds = baked->trace_seconds;
    // The maps stored in the low-poly's tangent basis: a runtime needs the basis they were baked in.
    const bool tangent_basis = std::ranges::any_of(options.request.bake.maps, [](Map m) { return m == Map::normal || m == Map::bent_normal; });
    gltf::ImageCache cache(*doc, options.encoding, gltf::MadeFormat::png);
    const auto ranges = material_ranges(*targets, *baked);
    for (std::size_t t = 0; t < targets->targets.size(); ++t) {
      auto written = write_maps(*doc, cache, options, *targets, t, into[t], file_names[t], ranges[t], baked->textures[t]);
      if (!written) return written.error();
      if (into[t] != targets->materials[t]) {
        written->copy_of = gltf::name_in(doc->json["materials"][std::size_t(targets->materials[t])], "");
        written->copy_of_material = targets->materials[t];
      }
      for (std::size_t i = 0; i < options.request.bake.maps.size(); ++i) {
        if (material_slot(options.request.bake.maps[i])) continue;
        report.beside.push_back(written->files[i]);
      }
      report.textures.push_back(std::move(*written));
    }
    // Before the tangents: a vertex they split gathers these attributes with the others.
    if (!options.request.bake.vertex_maps.empty()) {
      write_vertex_maps(*doc, *low, baked->vertices, options.request.vertex_ao_into, options.request.per_instance, report);
    }
    Renumbered renumbered;
    if (tangent_basis) {
      if (Status s = write_tangents(*doc, *low, *targets, report, renumbered); !s) return s.error();
    }
    if (tiles) {  // after the tangents: the triangles as they are written
      if (Status s = split_by_tile(*doc, *low, *tiles, into, renumbered); !s) return s.error();
    }
    if (const auto removed = gltf::prune_unreachable(*doc, nullptr, &as_read); !removed.empty()) {
      report.notes.push_back("removed what the bake left unused: " + join(removed, ", "));
    }
    auto written = gltf::write_document(*doc, options.output);
    if (!written) return written.error();
    for (const fs::path& p : *written) report.written.push_back(p.string());
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
  });
}

}  // namespace matbake::bake
