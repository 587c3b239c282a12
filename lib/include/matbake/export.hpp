#pragma once
// `matbake export`: a glTF scene written again as clean glTF 2.0 metal-rough.
// - Materials given maps from outside (a Schüler pair, or any pack layout's textures) and materials
//   in KHR_materials_pbrSpecularGlossiness are converted to pbrMetallicRoughness (the workflow
//   module's least squares and fitted gloss → roughness), with their error reported; a dielectric
//   whose F0 is not 0.04 gets KHR_materials_specular. Alpha comes from the mask: OPAQUE, MASK (only
//   0 and 1) or BLEND.
// - Occlusion and metallic-roughness textures of one material are packed into one ORM texture.
// - Per-vertex AO is baked in when asked (COLOR_0 or _AO).
// - Only what the default scene reaches is written; the report lists what was left out. A texture
//   shared by several materials is decoded and converted once. Same inputs, same bytes.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "matbake/ao.hpp"
#include "matbake/pack.hpp"
#include "matbake/result.hpp"
#include "matbake/workflow_maps.hpp"

namespace matbake::exporter {

// A material's maps from outside the glTF, replacing what it had.
struct MaterialMaps {
  std::string material;  // the glTF material's name (or its index, as a number)
  pack::SourceMaps maps;  // kd, ks, gloss (Schüler) or base_color, metallic, roughness; mask, occlusion optional
};

// How a converted dielectric whose F0 is not 0.04 says so: KHR_materials_specular's
// specularColorFactor = F0 / 0.04 (the IOR stays 1.5), or KHR_materials_ior's IOR from F0 =
// ((n − 1)/(n + 1))² (which also bends refraction, for transmissive materials), or neither.
enum class DielectricF0 { specular, ior, none };

struct Options {
  std::vector<MaterialMaps> materials;
  DielectricF0 dielectric_f0 = DielectricF0::specular;
  workflow::RoughnessMapping mapping = workflow::RoughnessMapping::fitted;
  bool pack_orm = true;           // occlusion + metallic-roughness into one texture
  std::optional<ao::Options> ao;  // bake per-vertex AO when set
  ao::Into ao_into = ao::Into::color_multiply;
};

struct MaterialReport {
  int index = -1;
  std::string name;
  std::string action;  // what was done: "kept", "converted from ...", "ORM packed"
  std::optional<workflow::ConversionReport> conversion;
  std::string alpha_mode;  // as written
  std::optional<double> specular_color_factor;  // KHR_materials_specular, when written
  std::optional<double> ior;                    // KHR_materials_ior, when written
};

struct Report {
  std::vector<MaterialReport> materials;  // every written material, in output order
  std::vector<std::string> skipped;       // what the scene does not reach: "material 2 'Unused'"
  std::vector<std::string> written;       // files, the .gltf or .glb last
  std::size_t images_decoded = 0;
  std::size_t textures_made = 0;
  std::uint64_t ao_rays = 0;
};

Result<Report> export_scene(const std::filesystem::path& input, const std::filesystem::path& output,
                            const Options& options);

}  // namespace matbake::exporter
