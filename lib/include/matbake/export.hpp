#pragma once
// `matbake export`: a glTF scene written again as clean glTF 2.0 metal-rough.
// - Materials given maps from outside (a Schüler pair, or any pack layout's textures) and materials
//   in KHR_materials_pbrSpecularGlossiness are converted to pbrMetallicRoughness (the workflow
//   module's least squares and fitted gloss → roughness), with their error reported; a dielectric
//   whose F0 is not 0.04 gets KHR_materials_specular. Alpha comes from the mask: OPAQUE, MASK (only
//   0 and 1) or BLEND.
// - Occlusion and metallic-roughness textures of one material are packed into one ORM texture.
// - AO is baked in when asked: per vertex (COLOR_0 or _AO), or as textures over the UVs, each into
//   the red channel of the material's ORM texture.
// - Only what the default scene reaches is written; the report lists what was left out. A texture
//   shared by several materials is decoded and converted once. Same inputs, same bytes.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "matbake/ao.hpp"
#include "matbake/bake_ao.hpp"
#include "matbake/delivery.hpp"
#include "matbake/pack.hpp"
#include "matbake/result.hpp"
#include "matbake/stage.hpp"
#include "matbake/workflow_maps.hpp"

namespace matbake::exporter {

// A material's maps from outside the glTF, replacing what it had (its spec-gloss, specular and IOR
// extensions included: the maps say what F0 is).
struct MaterialMaps {
  std::string material;  // the glTF material's name (or its index, as a number)
  material::Maps maps;  // kd, ks, gloss (Schüler) or base_color, metallic, roughness; mask, occlusion optional
  std::optional<workflow::RoughnessMapping> mapping;  // for Schüler maps; unset: Options::mapping
  std::vector<std::string> copies;  // other glTF materials that take the same maps (a bake's per-placement copies)
};

// How a converted dielectric whose F0 is not 0.04 says so: KHR_materials_specular's
// specularColorFactor = F0 / 0.04 (the IOR stays 1.5), or KHR_materials_ior's IOR from F0 =
// ((n − 1)/(n + 1))² (which also bends refraction, for transmissive materials), or neither.
enum class DielectricF0 { specular, ior, none };
inline constexpr NameTable<DielectricF0, 3> kDielectricF0Names{
    {{DielectricF0::specular, "specular"}, {DielectricF0::ior, "ior"}, {DielectricF0::none, "none"}}};

struct Options {
  std::vector<MaterialMaps> materials;
  DielectricF0 dielectric_f0 = DielectricF0::specular;
  workflow::RoughnessMapping mapping = workflow::kDefaultRoughnessMapping;
  bool pack_orm = true;           // occlusion + metallic-roughness into one texture
  image::Encoding encoding;       // of the PNGs it makes (converted, ORM and occlusion textures)
  delivery::Options delivery;     // sizes and KTX2 of every texture the scene uses
  std::optional<ao::Request> ao;  // bake AO when set: per vertex, or with ao->texture into each
                                  // material's ORM texture (red), or its own occlusion texture
  StageReport stage;  // not a parameter: told what the export is doing (a build's progress)
  // Not a parameter: only plan (`matbake inspect MANIFEST`): materials converted and AO textures
  // made at their sizes with one ray a texel, then Report::textures is delivery's plan
  // (delivery::plan_textures: sizes, codecs, estimated bytes); nothing is encoded or written.
  bool plan_only = false;
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
  std::vector<bake_ao::TextureReport> ao_textures;  // with ao.texture: each material's baked occlusion
  std::vector<std::string> ao_notes;       // what the texture bake skipped or averaged
  std::vector<std::string> geometry;       // compressed or sparse geometry: decoded to read, written back
                                           // as it came or uncompressed (gltf::geometry_notes)
  std::vector<delivery::TextureReport> textures;  // what delivery did to each used texture
};

Result<Report> export_scene(const std::filesystem::path& input, const std::filesystem::path& output,
                            const Options& options);

// The files a glTF is read from (itself, its buffers' and images' files): what no output may be.
Result<std::vector<std::filesystem::path>> scene_files(const std::filesystem::path& gltf);

}  // namespace matbake::exporter
