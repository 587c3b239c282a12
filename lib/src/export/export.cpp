#include "matbake/join.hpp"
#include "matbake/export.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "../gltf/decode.hpp"
#include "../gltf/document.hpp"
#include "../gltf/prune.hpp"
#include "../scene/from_document.hpp"
#include "../bake_ao/vertices.hpp"
#include "../bake_ao/textures.hpp"
#include "../delivery/deliver.hpp"
#include "../delivery/geometry.hpp"
#include "matbake/output_check.hpp"
#include "../gltf/texture_files.hpp"

namespace matbake::exporter {
namespace fs = std::filesystem;
using gltf::Json;
namespace {

// An integer of the glTF (a texture index, a texCoord set) read safely: INT_MAX, which no texture
// or set has, when it is not an int (gltf::integer_in).
int int_in(const gltf::Json& object, const char* key, int fallback) {
  return gltf::integer_in(object, key, fallback, std::numeric_limits<int>::max());
}

constexpr const char* kSpecGloss = "KHR_materials_pbrSpecularGlossiness";
constexpr const char* kSpecular = "KHR_materials_specular";
constexpr const char* kIor = "KHR_materials_ior";
constexpr const char* kEmissiveStrength = "KHR_materials_emissive_strength";
constexpr double kF0Tolerance = 0.001;  // below an 8-bit sRGB step at F0 0.04 (0.0014)

// A factor of `object` (as many numbers as `fallback` has; `fallback` when absent).
Result<std::vector<double>> numbers(const Json& object, const char* key, std::vector<double> fallback,
                                    const std::string& file, const std::string& where) {
  if (!object.contains(key)) return fallback;
  const Json& value = object[key];
  const bool scalar = fallback.size() == 1;
  if (scalar ? !value.is_number() : !value.is_array() || value.size() != fallback.size() ||
                                        !std::all_of(value.begin(), value.end(), [](const Json& v) { return v.is_number(); })) {
    return Error{file, where + "." + key + " must be " + (scalar ? "a number" : std::to_string(fallback.size()) + " numbers")};
  }
  if (scalar) return std::vector<double>{value.get<double>()};
  std::vector<double> out;
  for (const Json& v : value) out.push_back(v.get<double>());
  return out;
}

// Whether every texel of a 3-channel map is `value`.
bool uniform(const image::Image& map, std::initializer_list<float> value) {
  for (std::size_t i = 0; i < map.pixels.size(); ++i) {
    if (map.pixels[i] != value.begin()[i % 3]) return false;
  }
  return true;
}

void add_extension_used(Json& json, const char* name) {
  Json& used = json["extensionsUsed"];
  if (std::find(used.begin(), used.end(), name) == used.end()) used.push_back(name);
}

// What the export is doing, shared by the per-material steps.
struct Exporter {
  gltf::Document& doc;
  gltf::ImageCache& cache;
  const Options& options;
  std::string stem;  // of the output: names of the files made
  Report& report;
  std::map<std::string, Json> converted;         // spec-gloss block → the metal-rough it became
  std::map<std::pair<int, int>, int> orm_made;   // (metallic-roughness, occlusion) texture → ORM texture

  // A new texture over a new image file (the encoding's format), with the sampler of texture
  // `sampler_of` (none when −1).
  Result<int> add_texture(const image::Image& img, color::Transfer colour, const std::string& name, int sampler_of) {
    auto made = cache.add_texture(doc, img, colour, stem + "_" + name, sampler_of);
    if (!made) return made.error();
    ++report.textures_made;
    return made->index;
  }

  // The metal-rough maps written into `material`: factors when they are 1×1 (constants), else a
  // base colour texture (with the mask as alpha) and a metallic-roughness one (ORM with occlusion).
  Status write_metal_rough(Json& material, const material::Maps& maps, const std::string& name, Json texture_info,
                           int sampler_of) {
    Json& pbr = material["pbrMetallicRoughness"];
    pbr = Json::object();
    const image::Image& base = *maps.find(material::kBaseColor);
    const image::Image* mask = maps.find(material::kMask);
    if (maps.width == 1 && maps.height == 1) {
      pbr["baseColorFactor"] = {base.pixels[0], base.pixels[1], base.pixels[2], mask ? mask->pixels[0] : 1.0f};
      pbr["metallicFactor"] = maps.find(material::kMetallic)->pixels[0];
      pbr["roughnessFactor"] = maps.find(material::kRoughness)->pixels[0];
      return success();
    }
    const bool orm = maps.find(material::kOcclusion) != nullptr;
    auto layout = pack::find_layout(orm ? "gltf-orm" : "gltf-metal-rough");
    if (!layout) return layout.error();
    auto images = pack::pack(*layout, maps);
    if (!images) return images.error();
    auto base_texture = add_texture((*images)[0], color::Transfer::srgb, name + "_base_color", sampler_of);
    if (!base_texture) return base_texture.error();
    auto mr_texture = add_texture((*images)[1], color::Transfer::linear, name + (orm ? "_orm" : "_metallic_roughness"), sampler_of);
    if (!mr_texture) return mr_texture.error();
    texture_info["index"] = *base_texture;
    pbr["baseColorTexture"] = texture_info;
    texture_info["index"] = *mr_texture;
    pbr["metallicRoughnessTexture"] = texture_info;
    if (orm) {
      Json occlusion = material.value("occlusionTexture", Json::object());
      occlusion["index"] = *mr_texture;
      occlusion["texCoord"] = int_in(texture_info, "texCoord", 0);
      material["occlusionTexture"] = occlusion;
    }
    return success();
  }

  // A given normal map as normalTexture (none when flat: every texel +Z) and a given emissive map as
  // emissiveTexture with factor 1 (a constant one as emissiveFactor; none when black). They replace
  // the material's own.
  Status write_normal_and_emissive(Json& material, const material::Maps& given, const std::string& name, Json texture_info,
                                   int sampler_of, MaterialReport& out) {
    if (const image::Image* normal = given.find(material::kNormal)) {
      material.erase("normalTexture");
      if (!uniform(*normal, {0.5f, 0.5f, 1.0f})) {
        auto texture = add_texture(*normal, color::Transfer::linear, name + "_normal", sampler_of);
        if (!texture) return texture.error();
        Json info = {{"index", *texture}};
        if (texture_info.contains("texCoord")) info["texCoord"] = texture_info["texCoord"];
        material["normalTexture"] = info;
        out.action += "; normal map";
      }
    }
    if (const image::Image* emissive = given.find(material::kEmissive)) {
      if (Status s = write_emissive(material, *emissive, name, texture_info, sampler_of, out); !s) return s;
    }
    return success();
  }

  // A given emissive map replaces the material's emission: emissiveFactor for a constant (none when
  // black), else emissiveTexture. Emission above 1 (HDR, from EXR sources) is divided by its
  // maximum m, which KHR_materials_emissive_strength carries (strength m): nothing is clipped, and
  // the texture's 8 bits span the map's own range.
  Status write_emissive(Json& material, const image::Image& emissive, const std::string& name, Json texture_info,
                        int sampler_of, MaterialReport& out) {
    material.erase("emissiveTexture");
    material.erase("emissiveFactor");
    if (material.contains("extensions")) material["extensions"].erase(kEmissiveStrength);
    const float peak = *std::max_element(emissive.pixels.begin(), emissive.pixels.end());
    const float strength = std::max(peak, 1.0f);
    image::Image scaled = emissive;
    for (float& v : scaled.pixels) v /= strength;
    if (uniform(scaled, {scaled.pixels[0], scaled.pixels[1], scaled.pixels[2]})) {
      if (peak == 0) return success();
      material["emissiveFactor"] = {scaled.pixels[0], scaled.pixels[1], scaled.pixels[2]};
    } else {
      auto texture = add_texture(scaled, color::Transfer::srgb, name + "_emissive", sampler_of);
      if (!texture) return texture.error();
      texture_info["index"] = *texture;
      material["emissiveTexture"] = texture_info;
      material["emissiveFactor"] = {1.0, 1.0, 1.0};
      out.action += "; emissive map";
    }
    if (strength > 1) {
      material["extensions"][kEmissiveStrength] = {{"emissiveStrength", strength}};
      add_extension_used(doc.json, kEmissiveStrength);
      out.action += " (emissive strength " + std::to_string(strength) + ")";
    }
    return success();
  }

  // KHR_materials_specular or KHR_materials_ior for dielectric texels whose F0 is not glTF's 0.04.
  void add_dielectric_f0(Json& material, const workflow::ConversionReport& conversion, MaterialReport& out) {
    const auto& d = conversion.dielectric;
    if (d.texels == 0 || std::abs(d.mean_f0 - workflow::kDielectricF0) <= kF0Tolerance || options.dielectric_f0 == DielectricF0::none) return;
    if (options.dielectric_f0 == DielectricF0::specular) {
      const double f = d.specular_color_factor;
      material["extensions"][kSpecular] = {{"specularColorFactor", {f, f, f}}};
      add_extension_used(doc.json, kSpecular);
      out.specular_color_factor = f;
    } else {
      material["extensions"][kIor] = {{"ior", d.ior}};
      add_extension_used(doc.json, kIor);
      out.ior = d.ior;
    }
  }

  // Alpha from a mask map: none or all 1 → OPAQUE, only 0 and 1 → MASK, else BLEND.
  void set_alpha_mode(Json& material, const image::Image* mask) {
    if (!mask) return;
    const auto& v = mask->pixels;
    if (std::all_of(v.begin(), v.end(), [](float a) { return a >= 1.0f; })) {
      material.erase("alphaMode");
      material.erase("alphaCutoff");
    } else if (std::all_of(v.begin(), v.end(), [](float a) { return a <= 0.0f || a >= 1.0f; })) {
      material["alphaMode"] = "MASK";
      material["alphaCutoff"] = 0.5;
    } else {
      material["alphaMode"] = "BLEND";
      material.erase("alphaCutoff");
    }
  }

  // KHR_materials_pbrSpecularGlossiness's factors and textures as Schüler sources (kd, ks, gloss,
  // and the diffuse alpha as mask), at the size of the larger texture.
  Result<material::Maps> spec_gloss_sources(int index, const Json& ext) {
    const std::string where = "material " + std::to_string(index) + " " + kSpecGloss;
    auto diffuse_factor = numbers(ext, "diffuseFactor", {1, 1, 1, 1}, doc.file, where);
    auto specular_factor = numbers(ext, "specularFactor", {1, 1, 1}, doc.file, where);
    auto gloss_factor = numbers(ext, "glossinessFactor", {1}, doc.file, where);
    for (const auto* r : {&diffuse_factor, &specular_factor, &gloss_factor}) {
      if (!*r) return r->error();
    }
    const std::vector<double>& diffuse = *diffuse_factor;
    const std::vector<double>& specular = *specular_factor;
    const double gloss = (*gloss_factor)[0];
    const image::Image* textures[2] = {nullptr, nullptr};
    const char* keys[2] = {"diffuseTexture", "specularGlossinessTexture"};
    if (ext.contains(keys[0]) && ext.contains(keys[1])) {
      const auto mapping = [](const Json& info) { return Json{info.value("texCoord", Json(0)), info.value("extensions", Json::object())}; };
      if (mapping(ext[keys[0]]) != mapping(ext[keys[1]])) {
        return Error{doc.file, "/materials/" + std::to_string(index) + "/extensions/" + kSpecGloss +
                                   ": diffuseTexture and specularGlossinessTexture are mapped differently (texCoord or "
                                   "KHR_texture_transform); matbake converts them texel by texel and needs one mapping"};
      }
    }
    int width = 1, height = 1;
    for (int t = 0; t < 2; ++t) {
      if (!ext.contains(keys[t])) continue;
      // Both store colour sRGB-encoded and alpha (opacity, gloss) linear.
      auto im = cache.texture(int_in(ext[keys[t]], "index", -1), color::Transfer::srgb);
      if (!im) return im.error();
      textures[t] = *im;
      if (std::size_t((*im)->width) * (*im)->height > std::size_t(width) * height) width = (*im)->width, height = (*im)->height;
    }
    const image::Image d = textures[0] ? gltf::at_size(*textures[0], width, height) : image::Image{};
    const image::Image s = textures[1] ? gltf::at_size(*textures[1], width, height) : image::Image{};
    material::Maps maps;
    maps.width = width, maps.height = height;
    image::Image kd = gltf::blank(width, height, 3), ks = gltf::blank(width, height, 3), g = gltf::blank(width, height, 1),
                 alpha = gltf::blank(width, height, 1);
    for (std::size_t p = 0; p < std::size_t(width) * height; ++p) {
      for (int c = 0; c < 3; ++c) {
        kd.pixels[p * 3 + std::size_t(c)] = float(diffuse[std::size_t(c)]) * (textures[0] ? gltf::rgba(d, p, c) : 1.0f);
        ks.pixels[p * 3 + std::size_t(c)] = float(specular[std::size_t(c)]) * (textures[1] ? gltf::rgba(s, p, c) : 1.0f);
      }
      g.pixels[p] = float(gloss) * (textures[1] ? gltf::rgba(s, p, 3) : 1.0f);
      alpha.pixels[p] = float(diffuse[3]) * (textures[0] ? gltf::rgba(d, p, 3) : 1.0f);
    }
    maps.maps["kd"] = std::move(kd);
    maps.maps["ks"] = std::move(ks);
    maps.maps["gloss"] = std::move(g);
    maps.maps["mask"] = std::move(alpha);
    return maps;
  }

  Status from_spec_gloss(int index, Json& material, MaterialReport& out) {
    const Json ext = material["extensions"][kSpecGloss];
    material["extensions"].erase(kSpecGloss);
    if (material["extensions"].empty()) material.erase("extensions");
    const std::string key = ext.dump();
    out.action = "converted from " + std::string(kSpecGloss);
    if (const auto done = converted.find(key); done != converted.end()) {
      material["pbrMetallicRoughness"] = done->second["pbr"];
      if (done->second.contains("extensions")) {
        for (const auto& [name, value] : done->second["extensions"].items()) material["extensions"][name] = value;
        const Json& extensions = material["extensions"];
        if (extensions.contains(kSpecular)) out.specular_color_factor = extensions[kSpecular]["specularColorFactor"][0].get<double>();
        if (extensions.contains(kIor)) out.ior = extensions[kIor]["ior"].get<double>();
      }
      out.action += " (same as an earlier material: its textures reused)";
      return success();
    }
    auto sources = spec_gloss_sources(index, ext);
    if (!sources) return sources.error();
    workflow::ConversionReport conversion;
    auto maps = workflow::metal_rough_from_spec_gloss(*sources, options.mapping, conversion);
    if (!maps) return Error{doc.file, "material " + std::to_string(index) + ": " + maps.error().message};
    // The converted textures are mapped as their sources were (texCoord, KHR_texture_transform).
    const char* mapped_by = ext.contains("diffuseTexture") ? "diffuseTexture" : "specularGlossinessTexture";
    Json info = ext.contains(mapped_by) ? ext[mapped_by] : Json::object();
    info.erase("index");
    const int sampler_of = ext.contains(mapped_by) ? int_in(ext[mapped_by], "index", -1) : -1;
    if (Status s = write_metal_rough(material, *maps, gltf::material_file_name(material, index), info, sampler_of); !s) return s;
    add_dielectric_f0(material, conversion, out);
    out.conversion = conversion;
    Json remembered = {{"pbr", material["pbrMetallicRoughness"]}};
    if (out.specular_color_factor || out.ior) {
      remembered["extensions"] = Json::object();
      for (const char* name : {kSpecular, kIor}) {
        if (material["extensions"].contains(name)) remembered["extensions"][name] = material["extensions"][name];
      }
    }
    converted[key] = remembered;
    return success();
  }

  Status from_maps(int index, Json& material, const MaterialMaps& replacement, MaterialReport& out) {
    const material::Maps& given = replacement.maps;
    // The new maps say what the surface is: what described it before goes (spec-gloss and its
    // textures, a specular or IOR extension that would change the new F0).
    if (material.contains("extensions")) {
      for (const char* name : {kSpecGloss, kSpecular, kIor}) material["extensions"].erase(name);
      if (material["extensions"].empty()) material.erase("extensions");
    }
    Json info = Json::object();
    int sampler_of = -1;
    if (material.contains("pbrMetallicRoughness") && material["pbrMetallicRoughness"].contains("baseColorTexture")) {
      info = material["pbrMetallicRoughness"]["baseColorTexture"];
      sampler_of = int_in(info, "index", -1);
      info.erase("index");
    }
    const std::string name = gltf::material_file_name(material, index);
    if (given.find(material::kKd)) {
      workflow::ConversionReport conversion;
      auto maps = workflow::metal_rough_from_spec_gloss(given, replacement.mapping.value_or(options.mapping), conversion);
      if (!maps) return Error{doc.file, "material " + std::to_string(index) + ": " + maps.error().message};
      if (Status s = write_metal_rough(material, *maps, name, info, sampler_of); !s) return s;
      add_dielectric_f0(material, conversion, out);
      out.conversion = conversion;
      out.action = "from Schüler maps";
    } else {
      if (Status s = write_metal_rough(material, given, name, info, sampler_of); !s) return s;
      out.action = "from metal-rough maps";
    }
    if (Status s = write_normal_and_emissive(material, given, name, info, sampler_of, out); !s) return s;
    set_alpha_mode(material, given.find(material::kMask));
    return success();
  }

  // Occlusion and metallic-roughness in two textures of the same texCoord become one ORM texture.
  Status pack_orm(int index, Json& material, MaterialReport& out) {
    if (!material.contains("occlusionTexture") || !material.contains("pbrMetallicRoughness") ||
        !material["pbrMetallicRoughness"].contains("metallicRoughnessTexture")) {
      return success();
    }
    Json& mr = material["pbrMetallicRoughness"]["metallicRoughnessTexture"];
    Json& occlusion = material["occlusionTexture"];
    const int mr_index = int_in(mr, "index", -1), occlusion_index = int_in(occlusion, "index", -1);
    if (mr_index == occlusion_index) return success();  // already one texture
    // One texture has one mapping: maps with different UV sets or KHR_texture_transforms stay apart.
    const Json no_extensions = Json::object();
    if (int_in(mr, "texCoord", 0) != int_in(occlusion, "texCoord", 0) ||
        mr.value("extensions", no_extensions) != occlusion.value("extensions", no_extensions)) {
      out.action = (out.action == "kept" ? "" : out.action + "; ") +
                   "occlusion and metallic-roughness kept apart (mapped differently: texCoord or KHR_texture_transform)";
      return success();
    }
    int orm = -1;
    if (const auto found = orm_made.find({mr_index, occlusion_index}); found != orm_made.end()) {
      orm = found->second;
    } else {
      auto mr_image = cache.texture(mr_index, color::Transfer::linear);
      if (!mr_image) return mr_image.error();
      auto occlusion_image = cache.texture(occlusion_index, color::Transfer::linear);
      if (!occlusion_image) return occlusion_image.error();
      const image::Image& m = **mr_image;
      const image::Image o = gltf::at_size(**occlusion_image, m.width, m.height);
      image::Image packed = gltf::blank(m.width, m.height, 3);
      for (std::size_t p = 0; p < std::size_t(m.width) * m.height; ++p) {
        packed.pixels[p * 3] = gltf::rgba(o, p, 0);
        packed.pixels[p * 3 + 1] = gltf::rgba(m, p, 1);
        packed.pixels[p * 3 + 2] = gltf::rgba(m, p, 2);
      }
      // Named after the first material that reads the pair.
      auto texture = add_texture(packed, color::Transfer::linear, gltf::material_file_name(material, index) + "_orm", mr_index);
      if (!texture) return texture.error();
      orm = orm_made[{mr_index, occlusion_index}] = *texture;
    }
    mr["index"] = orm;
    occlusion["index"] = orm;
    out.action = (out.action == "kept" ? "" : out.action + "; ") + "occlusion and metallic-roughness packed into ORM";
    return success();
  }
};

// The index of the material named `name` (or given as a number), or an error listing the names.
Result<int> material_index(const gltf::Document& doc, const std::string& name) {
  const std::size_t count = doc.json.contains("materials") ? doc.json["materials"].size() : 0;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < count; ++i) {
    const std::string n = gltf::name_in(doc.json["materials"][i], "");
    if (n == name || std::to_string(i) == name) return int(i);
    names.push_back(n.empty() ? std::to_string(i) : n);
  }
  return Error{doc.file, "no material '" + name + "' in the scene" + (names.empty() ? "" : " (it has: " + join(names, ", ") + ")"), true};
}

// Every texCoord a material's textures use must exist on every primitive drawing with it.
Status check_texture_coordinates(const gltf::Document& doc) {
  if (!doc.json.contains("meshes")) return success();
  for (std::size_t m = 0; m < doc.json["meshes"].size(); ++m) {
    const Json& mesh = doc.json["meshes"][m];
    for (std::size_t p = 0; mesh.contains("primitives") && p < mesh["primitives"].size(); ++p) {
      const Json& primitive = mesh["primitives"][p];
      if (!primitive.contains("material")) continue;
      const Json& material = doc.json["materials"][primitive["material"].get<std::size_t>()];
      std::string missing;
      const auto check = [&](const Json& info) {
        const std::string set = "TEXCOORD_" + std::to_string(int_in(info, "texCoord", 0));
        if (!primitive["attributes"].contains(set)) missing = set;
      };
      if (material.contains("pbrMetallicRoughness")) {
        for (const char* key : {"baseColorTexture", "metallicRoughnessTexture"}) {
          if (material["pbrMetallicRoughness"].contains(key)) check(material["pbrMetallicRoughness"][key]);
        }
      }
      for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) {
        if (material.contains(key)) check(material[key]);
      }
      if (!missing.empty()) {
        return Error{doc.file, "material " + primitive["material"].dump() + " has textures but mesh " + std::to_string(m) +
                                   " primitive " + std::to_string(p) + " has no " + missing};
      }
    }
  }
  return success();
}

}  // namespace

Result<std::vector<fs::path>> scene_files(const fs::path& gltf) {
  auto json = gltf::read_json(gltf);
  if (!json) return json.error();
  return gltf::source_files(gltf, *json);
}

Result<Report> export_scene(const fs::path& input, const fs::path& output, const Options& options) {
  return guarded(input.string(), [&]() -> Result<Report> {
    const std::string ext = output.extension().string();
    if (ext != ".gltf" && ext != ".glb") return Error{output.string(), "the output is .gltf or .glb", true};
    report_stage(options.stage, Phase::read, "reading the glTF");
    auto doc = gltf::read_document(input);
    if (!doc) return doc.error();
    std::optional<ao::Request> ao_request = options.ao;
    if (ao_request && options.plan_only) {
      // A plan needs AO textures' sizes and places, not their values; per-vertex AO makes no texture.
      if (ao_request->texture) {
        ao_request->options.samples = 1;
        ao_request->texture->dump.clear();
      } else {
        ao_request.reset();
      }
    }
    if (ao_request && ao_request->texture) {
      if (Status s = ao::check(*ao_request->texture, ao_request->options); !s) return s.error();
    }
    Report report;
    report.skipped = gltf::prune_unreachable(*doc);  // from here on, everything in doc is reachable
    for (std::string& s : report.skipped) s += ": not reachable from the default scene";
    // The flattened scene only when AO is baked: a plain export works on the document alone. Made
    // after pruning, so that its mesh and material indices are the written file's.
    std::optional<scene::Scene> scene;
    std::optional<bake_ao::OcclusionTargets> occlusion;
    if (ao_request) {
      auto flattened = scene::scene_from_document(*doc, {.texcoords = ao_request->texture.has_value()});
      if (!flattened) return flattened.error();
      scene = std::move(*flattened);
      if (ao_request->texture) {
        auto targets = bake_ao::occlusion_targets(*doc, *scene, *ao_request->texture);
        if (!targets) return targets.error();
        occlusion = std::move(*targets);
        if (const fs::path& dump = ao_request->texture->dump; !dump.empty()) {
          std::vector<NamedOutput> dumped;
          for (int m : occlusion->materials) dumped.push_back({bake_ao::dumped_texture(dump, output.stem().string(), m), "texture dump"});
          if (Status s = check_outputs(dumped, gltf::source_files(doc->file, doc->json)); !s) return s.error();
        }
      }
    }

    std::map<int, const MaterialMaps*> given;
    for (const MaterialMaps& m : options.materials) {
      for (const std::string& name : m.copies) {
        auto index = material_index(*doc, name);
        if (!index) return index.error();
        given[*index] = &m;
      }
      auto index = material_index(*doc, m.material);
      if (!index) return index.error();
      given[*index] = &m;
    }

    gltf::ImageCache cache(*doc, options.encoding, delivery::made_format(options.delivery));
    const std::size_t images_read = gltf::array_in(doc->json, "images").size();
    Exporter exporter{*doc, cache, options, output.stem().string(), report, {}, {}};
    const std::size_t materials = doc->json.contains("materials") ? doc->json["materials"].size() : 0;
    report_stage(options.stage, Phase::read, "converting " + std::to_string(materials) + " materials", 0.5);
    for (std::size_t i = 0; i < materials; ++i) {
      Json& material = doc->json["materials"][i];
      MaterialReport out;
      out.index = int(i);
      out.name = gltf::name_in(material, "");
      out.action = "kept";
      Status done = success();
      if (const auto maps = given.find(int(i)); maps != given.end()) {
        done = exporter.from_maps(int(i), material, *maps->second, out);
      } else if (material.contains("extensions") && material["extensions"].contains(kSpecGloss)) {
        done = exporter.from_spec_gloss(int(i), material, out);
      }
      if (done && options.pack_orm) done = exporter.pack_orm(int(i), material, out);
      if (!done) return done.error();
      out.alpha_mode = material.value("alphaMode", "OPAQUE");
      report.materials.push_back(std::move(out));
    }
    // The spec-gloss extension is gone from every material that had it; a replaced material may also
    // have dropped the last use of the specular or IOR extension.
    for (const char* extension : {kSpecGloss, kSpecular, kIor}) {
      const auto uses = [&](const Json& m) { return m.contains("extensions") && m["extensions"].contains(extension); };
      if (doc->json.contains("materials") && std::any_of(doc->json["materials"].begin(), doc->json["materials"].end(), uses)) {
        continue;
      }
      for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
        if (!doc->json.contains(list)) continue;
        Json& names = doc->json[list];
        names.erase(std::remove(names.begin(), names.end(), extension), names.end());
        if (names.empty()) doc->json.erase(list);
      }
    }
    if (Status s = check_texture_coordinates(*doc); !s) return s.error();

    if (occlusion) {
      ao::TextureBakes timing;
      auto textures = bake_ao::bake_occlusion_textures(*doc, *scene, cache, *ao_request, *occlusion, output.stem().string(),
                                              bake_ao::OcclusionInto::orm, timing, options.stage);
      if (!textures) return textures.error();
      report.ao_textures = std::move(*textures);
      report.ao_notes = occlusion->notes;
      report.ao_rays = timing.rays;
    } else if (ao_request) {
      report_stage(options.stage, Phase::ao, "AO per vertex, " + std::to_string(ao_request->options.samples) + " rays a vertex");
      auto baked = bake_ao::bake_into(*doc, *scene, *ao_request);
      if (!baked) return baked.error();
      report.ao_rays = baked->rays;
    }
    if (options.plan_only) {
      auto planned = delivery::plan_textures(*doc, cache, options.delivery);
      if (!planned) return planned.error();
      report.textures = std::move(*planned);
      (void)delivery::store_once(*doc, report.textures);  // numbered as the written file's textures
      return report;
    }
    auto delivered = delivery::deliver_textures(*doc, cache, options.delivery, output, options.stage);
    if (!delivered) return delivered.error();
    // The input's images that nothing decoded (passed through as they are) decode in full too.
    if (Status s = cache.check_undecoded(images_read); !s) return s.error();
    report.textures = std::move(*delivered);
    // What the conversions replaced (spec-gloss textures, separate occlusion maps, old colours) and
    // what delivery did (resized or KTX2 images).
    for (std::string& s : delivery::store_once(*doc, report.textures)) report.skipped.push_back(s + ": replaced");
    report.images_decoded = cache.decoded();
    if (options.delivery.geometry.any()) {
      auto geometry = delivery::deliver_geometry(*doc, options.delivery.geometry);
      if (!geometry) return geometry.error();
      report.geometry = std::move(*geometry);
    } else {
      report.geometry = gltf::geometry_notes(*doc);
    }

    report_stage(options.stage, Phase::write, "writing " + output.filename().string());
    auto written = gltf::write_document(*doc, output);
    if (!written) return written.error();
    for (const fs::path& p : *written) report.written.push_back(p.string());
    return report;
  });
}

}  // namespace matbake::exporter
