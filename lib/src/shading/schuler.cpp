// Schüler's model (GPU Pro, 2.5): e = 2^(12 g), the four Cook-Torrance simplifications of his
// appendix and the two-hemisphere light. His intensities fold the Lambertian 1/π into E.
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "matbake/shading.hpp"

namespace matbake::shading {
namespace {


// Normalized Blinn-Phong in Schüler's units: (1 + e)/2 (n·h)^e (appendix).
double schuler_d(const Geometry& g, double e) { return (1.0 + e) / 2.0 * std::pow(std::max(g.n_dot_h, 0.0), e); }

double lerp(double a, double b, double t) { return a + t * (b - a); }

}  // namespace

double schuler_exponent(double gloss) { return std::exp2(12.0 * gloss); }

double beckmann_m_from_exponent(double e) { return std::sqrt(2.0 / (e + 2.0)); }

double schuler_cook_torrance_full(const Geometry& g, double ks, double gloss) {
  if (g.n_dot_l <= 0.0 || g.n_dot_v <= 0.0) return 0.0;
  // π·D: the Beckmann NDF in Schüler's units. The IOR comes from Ks; Ks = 1 is a perfect mirror.
  const double m = beckmann_m_from_exponent(schuler_exponent(gloss));
  const double f = ks >= 1.0 ? 1.0 : fresnel_cook_torrance(g.l_dot_h, ior_from_f0(ks));
  return std::numbers::pi * beckmann_d(g.n_dot_h, m) * f * torrance_sparrow_g(g) / (4.0 * g.n_dot_v);
}

double schuler_cook_torrance_simplified(const Geometry& g, double ks, double gloss) {
  if (g.n_dot_l <= 0.0 || g.n_dot_v <= 0.0) return 0.0;
  const double d = schuler_d(g, schuler_exponent(gloss));
  const double f = fresnel_schuler(g.l_dot_h, ks);
  // l·h > 0 here: it is at least (n·l + n·v) / 2.
  const double geometric = std::min(2.0 * g.n_dot_h * std::min(g.n_dot_v, g.n_dot_l) / g.l_dot_h, 1.0);
  return d * f * geometric / (4.0 * g.n_dot_v);
}

double schuler_kelemen_szirmay_kalos(const Geometry& g, double ks, double gloss) {
  if (g.n_dot_l <= 0.0 || g.n_dot_v <= 0.0) return 0.0;
  const double d = schuler_d(g, schuler_exponent(gloss));
  return d * fresnel_schuler(g.l_dot_h, ks) / (4.0 * g.l_dot_h * g.l_dot_h) * g.n_dot_l;
}

double schuler_optimized(const Geometry& g, double ks, double gloss) {
  if (g.n_dot_l <= 0.0 || g.n_dot_v <= 0.0) return 0.0;
  const double e = schuler_exponent(gloss);
  const double l_dot_h3 = g.l_dot_h * g.l_dot_h * g.l_dot_h;
  return ks * (1.0 + e) / (8.0 * l_dot_h3) * std::pow(std::max(g.n_dot_h, 0.0), e) * g.n_dot_l;
}

double schuler_specular(SchulerVariant variant, const Geometry& g, double ks, double gloss) {
  switch (variant) {
    case SchulerVariant::full: return schuler_cook_torrance_full(g, ks, gloss);
    case SchulerVariant::simplified: return schuler_cook_torrance_simplified(g, ks, gloss);
    case SchulerVariant::kelemen_szirmay_kalos: return schuler_kelemen_szirmay_kalos(g, ks, gloss);
    case SchulerVariant::optimized: return schuler_optimized(g, ks, gloss);
  }
  return 0.0;
}

double schuler_specular_brdf(SchulerVariant variant, const Geometry& g, double ks, double gloss) {
  if (g.n_dot_l <= 0.0) return 0.0;
  return schuler_specular(variant, g, ks, gloss) / (std::numbers::pi * g.n_dot_l);
}

double hemisphere_diffuse(const Vec3& n, double kd, const HemisphereLight& light) {
  const double n_z = glm::normalize(n).z;
  return kd * lerp(light.lower, light.upper, (1.0 + n_z) / 2.0);
}

double hemisphere_specular(const Vec3& n, const Vec3& v, double ks, double gloss, const HemisphereLight& light) {
  const Vec3 un = glm::normalize(n), uv = glm::normalize(v);
  const double n_dot_v = std::max(glm::dot(un, uv), 0.0);
  const Vec3 r = 2.0 * glm::dot(un, uv) * un - uv;
  // clamp(r·z / (1 − g), −1, 1); at g = 1 the ramp has zero width: a step at the horizon.
  const double width = 1.0 - gloss;
  const double s = width > 0.0 ? std::clamp(r.z / width, -1.0, 1.0) : (r.z > 0.0) - (r.z < 0.0);
  // The article lerps with this s in [−1, 1]; read literally, s = −1 would extrapolate to
  // 2 E_lower − E_upper (negative light under a dark ground). Like the diffuse term's
  // (1 + n·z)/2, it is mapped to [0, 1].
  return fresnel_schuler(gloss * n_dot_v, ks) * lerp(light.lower, light.upper, (1.0 + s) / 2.0);
}

}  // namespace matbake::shading
