#include "matbake/report_json.hpp"

#include "matbake/ao_params.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/delivery_params.hpp"
#include "matbake/encoding_params.hpp"
#include "matbake/export_params.hpp"

namespace matbake {
namespace {

nlohmann::json rgb(const glm::dvec3& v) { return {v.r, v.g, v.b}; }

nlohmann::json stats_json(const std::array<validate::ChannelStats, 3>& s) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : s) j.push_back({{"min", c.min}, {"max", c.max}, {"mean", c.mean}});
  return j;
}

}  // namespace


nlohmann::json to_json(const workflow::ErrorStats& s) {
  return {{"mean", s.mean}, {"max", s.max}, {"max_at", {s.max_x, s.max_y}}, {"texels", s.count}};
}

nlohmann::json to_json(const workflow::ConversionErrors& e) {
  return {{"diffuse_delta_e_ab", to_json(e.diffuse_delta_e)}, {"specular_f0_abs", to_json(e.specular)},
          {"lobe_relative_rms", to_json(e.lobe)}};
}

nlohmann::json to_json(const workflow::DielectricF0& d) {
  return {{"texels", d.texels},
          {"mean_f0", d.mean_f0},
          {"KHR_materials_ior", {{"ior", d.ior}}},
          {"KHR_materials_specular", {{"specularColorFactor", d.specular_color_factor}}},
          {"error_without_extensions", to_json(d.error_without_extensions)},
          {"error_with_extensions", to_json(d.error_with_extensions)}};
}

nlohmann::json to_json(const workflow::LayoutMaps& converted, workflow::RoughnessMapping mapping) {
  if (!converted.direction) return nullptr;
  const workflow::ConversionReport& report = converted.report;
  nlohmann::json j = {{"direction", workflow::direction_name(*converted.direction)},
                      {"mapping", workflow::roughness_mapping_name(mapping)},
                      {"texels", report.texels},
                      {"errors", to_json(report.errors)}};
  if (*converted.direction == workflow::Direction::metal_rough_from_spec_gloss) {
    j["khronos_converter_errors"] = to_json(report.khronos_errors);
    j["dielectric_f0"] = to_json(report.dielectric);
  }
  return j;
}

nlohmann::json to_json(const validate::Report& r, const validate::Options& options) {
  const bool has_diffuse = r.has_diffuse;
  nlohmann::json classes, flags, worst = nlohmann::json::array();
  for (std::size_t c = 0; c < 5; ++c) classes[std::string(material_table::f0_class_name(material_table::F0Class(c)))] = r.class_counts[c];
  nlohmann::json meanings;
  for (int b = 0; b < validate::kFlagCount; ++b) {
    flags[std::string(validate::flag_name(b))] = r.flag_counts[std::size_t(b)];
    meanings[std::string(validate::flag_name(b))] = validate::flag_meaning(b, r.vocabulary);
  }
  for (const validate::Texel& t : r.worst) {
    worst.push_back({{"x", t.x}, {"y", t.y}, {"class", material_table::f0_class_name(t.f0_class)},
                     {"flags", validate::flag_names(t.flags)}, {"severity", t.severity}, {"f0", rgb(t.f0)},
                     {"diffuse", rgb(t.diffuse)}});
  }
  nlohmann::json doc = {{"width", r.width},         {"height", r.height},
                        {"texels", r.texels},       {"masked", r.masked},
                        {"checked", r.checked},     {"classes", classes},
                        {"flags", flags},           {"violations", r.violations},
                        {"vocabulary", validate::vocabulary_name(r.vocabulary)},
                        {"flag_meanings", meanings},
                        {"violation_fraction", r.violation_fraction()},
                        {"worst", worst},           {"f0_stats", stats_json(r.f0_stats)}};
  if (has_diffuse) doc["diffuse_stats"] = stats_json(r.diffuse_stats);
  if (options.material) {
    doc["material"] = {{"name", options.material->name},
                       {"tolerance", options.tolerance},
                       {"within", r.material_within},
                       {"share_within", r.checked ? double(r.material_within) / double(r.checked) : 0.0}};
  }
  return doc;
}

nlohmann::json to_json(const delivery::TextureReport& t) {
  nlohmann::json j = {{"texture", t.texture},
                      {"class", name_in(delivery::kTextureClassNames, t.texture_class)},
                      {"codec", name_in(delivery::kCodecNames, t.codec)},
                      {"file", t.uri},
                      {"source_size", {t.source.width, t.source.height}},
                      {"size", {t.delivered.width, t.delivered.height}},
                      {"materials", t.materials},
                      {"levels", t.levels},
                      {"source_bytes", t.source_bytes},
                      {"bytes", t.bytes}};
  if (!t.uri.empty()) j["reused"] = t.reused, j["seconds"] = t.seconds;  // a file made (KTX2, or a resized PNG or WebP)
  if (t.cache_rejected) j["cache_rejected"] = true;
  if (!t.level_error.empty()) {
    nlohmann::json& levels = j["level_error"] = nlohmann::json::array();
    for (const delivery::LevelError& l : t.level_error) {
      nlohmann::json& level = levels.emplace_back(nlohmann::json{{"psnr", l.psnr}});
      if (t.texture_class == delivery::TextureClass::normal) level["mean_angle"] = l.mean_angle, level["max_angle"] = l.max_angle;
      if (t.alpha_cutoff) level["coverage"] = l.coverage;
    }
  }
  if (t.needed) j["needed_side"] = *t.needed;
  if (t.alpha_cutoff) j["alpha_cutoff"] = *t.alpha_cutoff, j["coverage"] = t.coverage;
  if (!t.note.empty()) j["note"] = t.note;
  return j;
}

nlohmann::json delivered_json(const std::vector<delivery::TextureReport>& textures) {
  nlohmann::json out = nlohmann::json::array();
  for (const delivery::TextureReport& t : textures) out.push_back(to_json(t));
  return out;
}

nlohmann::json to_json(const exporter::Report& r) {
  nlohmann::json textures = nlohmann::json::array();
  for (const bake_ao::TextureReport& t : r.ao_textures) textures.push_back(to_json(t));
  nlohmann::json materials = nlohmann::json::array();
  for (const exporter::MaterialReport& m : r.materials) {
    nlohmann::json j = {{"index", m.index}, {"name", m.name}, {"action", m.action}, {"alphaMode", m.alpha_mode}};
    if (m.conversion) {
      j["texels"] = m.conversion->texels;
      j["errors"] = to_json(m.conversion->errors);
      j["khronos_converter_errors"] = to_json(m.conversion->khronos_errors);
      j["dielectric_f0"] = to_json(m.conversion->dielectric);
    }
    if (m.specular_color_factor) j["KHR_materials_specular"] = {{"specularColorFactor", *m.specular_color_factor}};
    if (m.ior) j["KHR_materials_ior"] = {{"ior", *m.ior}};
    materials.push_back(std::move(j));
  }
  return {{"materials", materials},           {"skipped", r.skipped},
          {"written", r.written},    {"images_decoded", r.images_decoded}, {"textures_made", r.textures_made},
          {"ao_rays", r.ao_rays},    {"ao_textures", textures}, {"ao_notes", r.ao_notes},
          {"geometry", r.geometry}, {"textures", delivered_json(r.textures)}};
}

Status write_validation_report(const validate::Report& r, const validate::Options& options,
                               const std::filesystem::path& json) {
  nlohmann::json v = to_json(r, options);
  v["max_violations"] = options.max_violations;
  v["passed"] = validate::passed(r, options);
  return write_file_atomically(json, v.dump(2) + "\n");
}

nlohmann::json to_json(const ao::Request& r) { return params::to_json(ao::request_params(), r); }

nlohmann::json to_json(const bake_ao::TextureReport& t) {
  return {{"material", t.material}, {"node", t.node}, {"name", t.name}, {"file", t.file}, {"width", t.width}, {"height", t.height},
          {"texcoord", t.texcoord}, {"covered", t.covered}, {"touched", t.touched}, {"overlapped", t.overlapped},
          {"padded", t.padded}, {"triangles", t.triangles}, {"degenerate_uv", t.degenerate_uv}, {"wrapped", t.wrapped},
          {"too_large", t.too_large}, {"instances_without_uv", t.instances_without_uv}, {"existing", t.existing}, {"orm", t.orm},
          {"mean_ao", t.mean}};
}

nlohmann::json to_json(const exporter::Options& o) { return params::tree_json(exporter::request_tree(), o); }

nlohmann::json to_json(const bake::FileReport& r) {
  nlohmann::json textures = nlohmann::json::array();
  for (const bake::TextureReport& t : r.textures) {
    textures.push_back({{"material", t.material}, {"name", t.name}, {"width", t.width}, {"height", t.height},
                        {"texcoord", t.texcoord}, {"texels", t.texels}, {"rays", t.samples}, {"misses", t.misses},
                        {"missed_texels", t.missed_texels}, {"padded", t.padded}, {"height_min", t.height_min},
                        {"height_max", t.height_max}, {"files", t.files}, {"existing", t.existing},
                        {"occlusion_rays", t.occlusion_rays}, {"from_inside", t.from_inside}, {"overlapped", t.overlapped},
                        {"outside_tile", t.outside_tile}, {"faced_away", t.faced_away}, {"skipped_triangles", t.skipped_triangles},
                        {"ranges", nlohmann::json::array()}});
    for (const auto& range : t.ranges) {  // per map: what a PNG's 0 and 1 stand for; null for an EXR
      textures.back()["ranges"].push_back(range ? nlohmann::json{range->first, range->second} : nlohmann::json());
    }
    if (t.copy_of_material >= 0) textures.back()["copy_of"] = t.copy_of, textures.back()["copy_of_material"] = t.copy_of_material;
    if (t.tile) textures.back()["tile"] = t.tile;
  }
  return {{"front", r.front}, {"back", r.back}, {"textures", textures}, {"tangent_primitives", r.tangent_primitives},
          {"split_vertices", r.split_vertices}, {"seconds", r.seconds}, {"setup_seconds", r.setup_seconds},
          {"trace_seconds", r.trace_seconds}, {"notes", r.notes}, {"warnings", r.warnings}, {"written", r.written}, {"reused", r.reused},
          {"vertices", {{"vertices", r.vertices.vertices}, {"misses", r.vertices.misses},
                        {"occlusion_rays", r.vertices.occlusion_rays}, {"attributes", r.vertices.attributes}}}};
}

}  // namespace matbake
