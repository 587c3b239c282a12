#pragma once
// Workflow conversion of whole source maps (material::Maps), per texel, with the error of the
// result measured against what was asked for.
#include "matbake/pack.hpp"
#include "matbake/result.hpp"
#include "matbake/workflow.hpp"

namespace matbake::workflow {

struct ErrorStats {
  double mean = 0;
  double max = 0;
  int max_x = 0, max_y = 0;  // where the maximum is
  std::size_t count = 0;     // texels measured
};

// One conversion's errors, each comparing what the converted material renders (glTF 2.0's
// c_diff = base (1 − m), F0 = lerp(0.04, base, m), GGX) with the source material:
//   diffuse: CIE 1976 ΔE*ab of the diffuse colour; specular: max over channels of |ΔF0|;
//   lobe: lobe_error() of the specular (Schüler's CookTorranceSimplified against GGX), on up to
//   kLobeTexels texels on a regular grid (it costs about 0.2 ms a texel).
struct ConversionErrors {
  ErrorStats diffuse_delta_e;
  ErrorStats specular;
  ErrorStats lobe;
};
inline constexpr std::size_t kLobeTexels = 1024;

// Dielectric texels (grey Ks, max − min ≤ 0.02, at most 0.2, Kd not black) whose F0 is not 0.04:
// core glTF says 0.04 for them; KHR_materials_ior (one IOR for the material, from the mean F0)
// or KHR_materials_specular (specularColorFactor = mean F0 / 0.04 with the default IOR 1.5) carry
// it. The errors are |ΔF0| without the extensions and with the per-material value.
struct DielectricF0 {
  std::size_t texels = 0;
  double mean_f0 = 0;
  double ior = 1.5;
  double specular_color_factor = 1;
  ErrorStats error_without_extensions;
  ErrorStats error_with_extensions;
};

struct ConversionReport {
  std::size_t texels = 0;
  ConversionErrors errors;          // of the conversion made
  ConversionErrors khronos_errors;  // spec-gloss → metal-rough only: the Khronos converter's, on the same texels
  DielectricF0 dielectric;          // spec-gloss → metal-rough only
};

// Needs kd, ks, gloss; writes base_color, metallic, roughness (and passes every other map through:
// mask, occlusion, detail_mask, normal, emissive).
Result<material::Maps> metal_rough_from_spec_gloss(const material::Maps& in, RoughnessMapping mapping,
                                                     ConversionReport& report);
// Needs base_color, metallic, roughness; writes kd, ks, gloss (the same pass-through).
Result<material::Maps> spec_gloss_from_metal_rough(const material::Maps& in, RoughnessMapping mapping,
                                                     ConversionReport& report);

// The maps in the workflow a layout reads: converted when they are all of the other workflow
// (Schüler maps for a metal-rough layout, or the reverse), else as they are (direction unset).
enum class Direction { metal_rough_from_spec_gloss, spec_gloss_from_metal_rough };
std::string_view direction_name(Direction d);  // "spec-gloss to metal-rough", "metal-rough to spec-gloss"
struct LayoutMaps {
  material::Maps maps;
  std::optional<Direction> direction;
  ConversionReport report;  // when converted
};
Result<LayoutMaps> in_layout_workflow(material::Maps maps, const pack::Layout& layout, RoughnessMapping mapping);
// The conversion in_layout_workflow makes, if any: of maps, or of maps with these names.
std::optional<Direction> layout_direction(const material::Maps& maps, const pack::Layout& layout);
std::optional<Direction> layout_direction(const material::MapNames& names, const pack::Layout& layout);
// The names of the maps in_layout_workflow returns for maps of these names (what a plan knows
// before any file is read).
material::MapNames names_in_layout_workflow(material::MapNames names, const pack::Layout& layout);

}  // namespace matbake::workflow
