#include "textures.hpp"

#include <algorithm>
#include <map>
#include <set>

#include "../gltf/texture_files.hpp"
#include "../gltf/placements.hpp"
#include "../gltf/texture_transform.hpp"

namespace matbake::bake_ao {
namespace fs = std::filesystem;
namespace {

using gltf::Json;

// The material's occlusionTexture, when it has a valid one.
const Json* occlusion_of(const Json& material, const Json& json) {
  if (!material.contains("occlusionTexture") || !material["occlusionTexture"].is_object()) return nullptr;
  const Json& info = material["occlusionTexture"];
  const auto index = gltf::size_in(info, "index", SIZE_MAX);
  return index < gltf::array_in(json, "textures").size() ? &info : nullptr;
}

// The material's metallic-roughness texture when it is mapped by `texcoord` (and untransformed):
// the one an ORM texture can share.
const Json* metallic_roughness_of(const Json& material, const Json& json, int texcoord) {
  if (!material.contains("pbrMetallicRoughness") || !material["pbrMetallicRoughness"].is_object()) return nullptr;
  const Json& pbr = material["pbrMetallicRoughness"];
  if (!pbr.contains("metallicRoughnessTexture") || !pbr["metallicRoughnessTexture"].is_object()) return nullptr;
  const Json& info = pbr["metallicRoughnessTexture"];
  if (gltf::size_in(info, "index", SIZE_MAX) >= gltf::array_in(json, "textures").size()) return nullptr;
  if (gltf::integer_in<int>(info, "texCoord", 0, -1) != texcoord || info.contains("extensions")) return nullptr;
  return &info;
}

bool has_transformed_metallic_roughness(const Json& material) {
  const Json* pbr = material.contains("pbrMetallicRoughness") ? &material["pbrMetallicRoughness"] : nullptr;
  if (pbr == nullptr || !pbr->is_object() || !pbr->contains("metallicRoughnessTexture")) return false;
  const Json& info = (*pbr)["metallicRoughnessTexture"];
  return info.is_object() && info.contains("extensions") && info["extensions"].contains("KHR_texture_transform");
}

const Json* sampler_of(const Json& json, std::size_t texture) {
  const Json& t = gltf::array_in(json, "textures")[texture];
  const auto sampler = gltf::size_in(t, "sampler", SIZE_MAX);
  const Json& samplers = gltf::array_in(json, "samplers");
  return sampler < samplers.size() ? &samplers[sampler] : nullptr;
}

// A primitive of the document using material `m` without TEXCOORD_<texcoord> ("mesh 2 primitive 0"),
// or "": an occlusion texture on the material would ask it for UVs it does not have.
std::string primitive_without_uvs(const Json& json, int m, int texcoord) {
  const Json& meshes = gltf::array_in(json, "meshes");
  const std::string name = "TEXCOORD_" + std::to_string(texcoord);
  for (std::size_t mesh = 0; mesh < meshes.size(); ++mesh) {
    const Json& primitives = gltf::array_in(meshes[mesh], "primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      if (gltf::integer_in<int>(primitives[p], "material", -1, -1) != m) continue;
      const Json& attributes = primitives[p].contains("attributes") ? primitives[p]["attributes"] : Json::object();
      if (!attributes.is_object() || !attributes.contains(name)) {
        return "mesh " + std::to_string(mesh) + " primitive " + std::to_string(p);
      }
    }
  }
  return "";
}

}  // namespace

Result<OcclusionTargets> occlusion_targets(const gltf::Document& doc, const scene::Scene& scene,
                                           const ao::TextureRequest& request) {
  OcclusionTargets out;
  const Json& materials = gltf::array_in(doc.json, "materials");
  std::map<std::pair<int, int>, std::vector<std::size_t>> by_material;  // (material, node or -1) → instances
  std::size_t without = 0;
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const int m = scene.instances[k].material;
    if (m == -1) {
      ++without;
      continue;
    }
    if (m < 0 || std::size_t(m) >= materials.size()) {
      return Error{doc.file, "mesh " + std::to_string(scene.instances[k].mesh) + " primitive " +
                                 std::to_string(scene.instances[k].primitive) + " refers to a material that does not exist"};
    }
    by_material[{m, request.per_instance ? scene.instances[k].node : -1}].push_back(k);
  }
  if (without) {
    out.notes.push_back(std::to_string(without) + " placed primitives have no material, so no occlusion texture" +
                        " (per-vertex AO can still be baked)");
  }
  for (const auto& [key, instances] : by_material) {
    const int m = key.first;
    const Json& material = materials[std::size_t(m)];
    const Json* existing = occlusion_of(material, doc.json);
    ao::TextureTarget target;
    target.instances = instances;
    target.name = "material " + std::to_string(m) + " '" + gltf::name_in(material, "") + "'";
    target.texcoord = request.texcoord >= 0 ? request.texcoord
                      : existing        ? gltf::integer_in<int>(*existing, "texCoord", 0, 0)
                                        : 0;
    if (const std::string lacking = primitive_without_uvs(doc.json, m, target.texcoord); !lacking.empty()) {
      out.notes.push_back("material " + std::to_string(m) + " is used by " + lacking + ", which has no TEXCOORD_" +
                          std::to_string(target.texcoord) + ": no occlusion texture (per-vertex AO can still be baked)");
      continue;
    }
    if (existing) {
      if (const Json* sampler = sampler_of(doc.json, gltf::size_in(*existing, "index", 0))) {
        target.wrap_s = gltf::wrap_of(*sampler, "wrapS");
        target.wrap_t = gltf::wrap_of(*sampler, "wrapT");
      }
    }
    // One texture cannot hold two placements of the same surface (without --per-instance).
    std::map<std::pair<int, int>, std::set<int>> nodes;  // (mesh, primitive) → placing nodes
    for (std::size_t k : instances) nodes[{scene.instances[k].mesh, scene.instances[k].primitive}].insert(scene.instances[k].node);
    for (const auto& [primitive, placing] : nodes) {
      if (placing.size() < 2) continue;
      out.notes.push_back("material " + std::to_string(m) + ": mesh " + std::to_string(primitive.first) + " primitive " +
                          std::to_string(primitive.second) + " is placed by " + std::to_string(placing.size()) +
                          " nodes; its texels hold the mean of the placements");
    }
    out.materials.push_back(m);
    out.nodes.push_back(key.second);
    out.targets.push_back(std::move(target));
  }
  if (out.targets.empty()) {
    return Error{doc.file, "no material the scene reaches can hold an occlusion texture (each needs a UV set on all its primitives)"};
  }
  return out;
}

fs::path dumped_texture(const fs::path& folder, const std::string& stem, int material) {
  return folder / (stem + "_occlusion_" + std::to_string(material) + ".exr");
}

Result<std::vector<TextureReport>> bake_occlusion_textures(gltf::Document& doc, const scene::Scene& scene,
                                                           gltf::ImageCache& cache, const ao::Request& request,
                                                           const OcclusionTargets& targets,
                                                           const std::string& stem, OcclusionInto into,
                                                           ao::TextureBakes& timing, const StageReport& stage) {
  const ao::TextureRequest& texture = *request.texture;
  auto baked = ao::bake_textures(scene, request.options, targets.targets, texture.size, stage);
  if (!baked) {
    Error error = baked.error();  // about the scene: named after its file (a usage error stays one)
    if (error.path.empty() && !error.usage) error.path = doc.file;
    return error;
  }
  const std::vector<int> materials = gltf::split_placements(doc, scene, targets.materials, targets.nodes);
  std::vector<TextureReport> reports;
  for (std::size_t t = 0; t < targets.targets.size(); ++t) {
    const int m = materials[t];
    ao::TextureBake& bake = baked->textures[t];
    Json& material = doc.json["materials"][std::size_t(m)];
    TextureReport report;
    report.material = m;
    report.node = targets.nodes[t];
    report.name = gltf::name_in(material, "");
    report.width = bake.width, report.height = bake.height, report.texcoord = targets.targets[t].texcoord;
    report.covered = bake.covered, report.touched = bake.touched, report.overlapped = bake.overlapped;
    report.padded = bake.padded, report.triangles = bake.triangles, report.degenerate_uv = bake.degenerate_uv;
    report.wrapped = bake.wrapped, report.too_large = bake.too_large, report.instances_without_uv = bake.instances_without_uv;
    report.mean = bake.mean;

    image::Image img = gltf::blank(bake.width, bake.height, 1);
    img.channel_names = {"Y"};
    img.pixels = std::move(bake.values);
    const Json* existing = occlusion_of(material, doc.json);
    int sampler_from = -1;
    if (existing) {
      const int old = gltf::integer_in<int>(*existing, "index", -1, -1);
      sampler_from = old;
      const int old_texcoord = gltf::integer_in<int>(*existing, "texCoord", 0, 0);
      const std::string where = "/materials/" + std::to_string(m) + "/occlusionTexture";
      auto transform = gltf::uv_transform_of(*existing, doc.file, where);
      if (!transform) return transform.error();
      const int mapped_by = transform->texcoord >= 0 ? transform->texcoord : old_texcoord;
      if (texture.multiply_existing && mapped_by == report.texcoord) {
        auto decoded = cache.texture(old, color::Transfer::linear);
        if (!decoded) return decoded.error();
        // The bake is over raw UVs; the file's texture is seen through its transform.
        const image::Image own = transform->identity() ? gltf::at_size(**decoded, bake.width, bake.height)
                                                       : gltf::sample_through(**decoded, *transform, targets.targets[t].wrap_s,
                                                                              targets.targets[t].wrap_t, bake.width, bake.height);
        for (std::size_t p = 0; p < img.pixels.size(); ++p) img.pixels[p] *= gltf::rgba(own, p, 0);
        report.existing = transform->identity() ? "multiplied" : "multiplied, sampled through its KHR_texture_transform";
      } else {
        report.existing = transform->identity() ? "replaced" : "replaced (its KHR_texture_transform with it: the bake is over raw UVs)";
      }
    }
    if (!texture.dump.empty()) {
      image::WriteOptions exr;
      exr.type = image::SampleType::f32;
      if (Status s = image::write_image(img, dumped_texture(texture.dump, stem, m), exr); !s) return s.error();
    }
    const Json* mr = into == OcclusionInto::orm ? metallic_roughness_of(material, doc.json, report.texcoord) : nullptr;
    if (into == OcclusionInto::orm && mr == nullptr && has_transformed_metallic_roughness(material)) {
      report.orm = "kept apart: the metallic-roughness texture has a KHR_texture_transform, the bake none";
    }
    int index = -1;
    if (mr) {
      // Red: the bake at the metallic-roughness texture's size; green and blue: that texture's.
      const int mr_index = gltf::integer_in<int>(*mr, "index", -1, -1);
      auto decoded = cache.texture(mr_index, color::Transfer::linear);
      if (!decoded) return decoded.error();
      const image::Image& source = **decoded;
      const image::Image occlusion = gltf::at_size(img, source.width, source.height);
      image::Image orm = gltf::blank(source.width, source.height, 3);
      for (std::size_t p = 0; p < std::size_t(source.width) * std::size_t(source.height); ++p) {
        orm.pixels[p * 3] = std::clamp(occlusion.pixels[p], 0.0f, 1.0f);  // the resize may ring past [0, 1]
        orm.pixels[p * 3 + 1] = gltf::rgba(source, p, 1);
        orm.pixels[p * 3 + 2] = gltf::rgba(source, p, 2);
      }
      auto made = cache.add_texture(doc, orm, color::Transfer::linear, stem + "_" + gltf::material_file_name(material, m) + "_orm_ao",
                                    mr_index);
      if (!made) return made.error();
      report.file = made->uri;
      index = made->index;
      material["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"] = index;
    } else {
      auto made = cache.add_texture(doc, img, color::Transfer::linear, stem + "_" + gltf::material_file_name(material, m) + "_occlusion", sampler_from,
                                    texture.bits == 16 ? image::SampleType::u16 : image::SampleType::u8);
      if (!made) return made.error();
      report.file = made->uri;
      index = made->index;
    }
    // A transform (KHR_texture_transform) of the old texture does not apply to UVs baked as they are.
    Json info = {{"index", index}};
    if (report.texcoord != 0) info["texCoord"] = report.texcoord;
    if (existing && existing->contains("strength")) info["strength"] = (*existing)["strength"];
    material["occlusionTexture"] = std::move(info);
    reports.push_back(std::move(report));
  }
  timing.rays = baked->rays;
  timing.max_distance = baked->max_distance;
  timing.setup_seconds = baked->setup_seconds;
  timing.texel_seconds = baked->texel_seconds;
  timing.ray_seconds = baked->ray_seconds;
  return reports;
}

}  // namespace matbake::bake_ao
