#pragma once
// Schüler's specular workflow (Kd, Ks, g) and glTF's metalness workflow (base colour, metallic,
// roughness), per texel, in linear float64, with the error of every conversion measured by the
// shading module. docs/workflow.md has the derivations and the measured tables.
#include <glm/vec3.hpp>

#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "matbake/enum_names.hpp"

namespace matbake::workflow {

using Vec3 = glm::dvec3;

// F0 that the metalness workflow gives every dielectric (glTF 2.0, the PBR notes).
inline constexpr double kDielectricF0 = 0.04;

struct SpecGloss {
  Vec3 kd{0.5};     // diffuse colour
  Vec3 ks{0.04};    // specular colour, F0
  double gloss = 0.5;  // g; Blinn-Phong exponent 2^(12 g)
};

struct MetalRough {
  Vec3 base{0.5};
  double metallic = 0;
  double roughness = 0.5;  // glTF perceptual roughness; GGX α = roughness²
};

// The metalness relation of the PBR notes: c_diff = base (1 − m), c_spec = lerp(0.04, base, m).
Vec3 diffuse_from_metal_rough(const Vec3& base, double metallic);
Vec3 specular_from_metal_rough(const Vec3& base, double metallic);

// --- Gloss ⇄ roughness --------------------------------------------------------------------------
enum class RoughnessMapping {
  // e = 2^(12 g) → Beckmann α = sqrt(2/(e + 2)) (Walter et al. 2007) → roughness = sqrt(α).
  walter,
  // Per (g, F0), the roughness whose GGX lobe is nearest to Schüler's CookTorranceSimplified lobe
  // in least squares (lobe_error below), tabulated at 33 glosses × the F0 values of
  // kFittedF0 and interpolated linearly in both (bench/fit_gloss_roughness prints the table and
  // both mappings' errors). The best roughness grows with F0 (Schüler's Fresnel and Schlick's
  // differ most for dielectrics), up to 0.14 at g = 0.
  fitted,
};
inline constexpr double kFittedF0[] = {0.02, 0.04, 0.2, 0.5, 0.8, 1.0};
// The mapping every front end uses unless told otherwise.
inline constexpr RoughnessMapping kDefaultRoughnessMapping = RoughnessMapping::fitted;
inline constexpr NameTable<RoughnessMapping, 2> kRoughnessMappingNames{
    {{RoughnessMapping::fitted, "fitted"}, {RoughnessMapping::walter, "walter"}}};
inline std::string_view roughness_mapping_name(RoughnessMapping m) { return name_in(kRoughnessMappingNames, m); }
// g in [0, 1] (clamped); both mappings are strictly decreasing in g, so each has an inverse for a
// given F0 (the mean of the specular colour's channels; walter ignores it).
double roughness_from_gloss(double gloss, RoughnessMapping mapping, double f0 = kDielectricF0);
double gloss_from_roughness(double roughness, RoughnessMapping mapping, double f0 = kDielectricF0);  // in [0, 1]
// The fitted table's row for kFittedF0[row]: roughness at g = i / 32.
std::span<const double> fitted_roughness_table(std::size_t row);

// --- Colour: (Kd, Ks) ⇄ (base, metallic) --------------------------------------------------------
struct BaseMetallic {
  Vec3 base{0};
  double metallic = 0;
};
// Least squares over the six equations base (1 − m) = Kd, lerp(0.04, base, m) = Ks: for a given m
// each base channel has a closed form, m is found by a bracketed 1-D search on [0, 1], base is
// clamped to [0, 1]. Explicit cases: Kd = Ks = 0 → black metal (m = 1, exact); Kd = 0 with
// Ks ≥ 0.04 → pure metal, base = Ks; Ks = 0.04 → pure dielectric, base = Kd.
BaseMetallic base_metallic_from_spec_gloss(const Vec3& kd, const Vec3& ks);
// The Khronos sample converter of KHR_materials_pbrSpecularGlossiness (solveMetallic on perceived
// brightness, base from a metallic²-weighted blend), for comparison.
BaseMetallic khronos_base_metallic(const Vec3& kd, const Vec3& ks);

// The mean of the channels: the F0 the fitted mapping is looked up with.
double mean_f0(const Vec3& specular);
MetalRough metal_rough_from_spec_gloss(const SpecGloss& material, RoughnessMapping mapping);
SpecGloss spec_gloss_from_metal_rough(const MetalRough& material, RoughnessMapping mapping);

// --- Errors -------------------------------------------------------------------------------------
// CIE 1976 ΔE*ab between two linear sRGB (Rec. 709 primaries, D65) colours.
double delta_e_ab(const Vec3& linear_a, const Vec3& linear_b);

// Directions for comparing specular lobes: views at polar angles 0°, 20°, 40°, 60°, 75°; for
// each, light directions from a (θ_h, φ) grid over the half vector, dense near the mirror
// direction (θ_h = (π/2) t²), with quadrature weights of dω_l. `steps` θ_h rows, 2·steps φ columns.
struct LobeQuadrature {
  struct Pair {
    double n_dot_l, n_dot_v, n_dot_h, l_dot_h, weight;
  };
  std::vector<Pair> pairs;
};
LobeQuadrature make_lobe_quadrature(int steps);

// Relative RMS over the quadrature of GGX(f0, roughness) against Schüler's CookTorranceSimplified
// (ks, gloss), both as n·l-weighted radiance: sqrt(Σ w (b − a)² / Σ w a²). Per channel when given
// colours (the channels' sums are added).
double lobe_error(const LobeQuadrature& q, double ks, double gloss, double f0, double roughness);
double lobe_error(const LobeQuadrature& q, const Vec3& ks, double gloss, const Vec3& f0, double roughness);
// The roughness minimizing lobe_error for (ks, gloss) with f0 = ks (golden-section search).
double best_roughness(const LobeQuadrature& q, double ks, double gloss);

}  // namespace matbake::workflow
