// The classic lobes, the Blinn-Phong family, Cook-Torrance, GGX and Oren-Nayar.
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "matbake/shading.hpp"

namespace matbake::shading {
namespace {

constexpr double kPi = std::numbers::pi;

bool lit_and_seen(const Geometry& g) { return g.n_dot_l > 0.0 && g.n_dot_v > 0.0; }

}  // namespace

double phong_lobe(const Geometry& g, double m) {
  return g.n_dot_l > 0.0 ? std::pow(std::max(g.r_dot_v, 0.0), m) : 0.0;
}

double blinn_phong_lobe(const Geometry& g, double m) {
  return g.n_dot_l > 0.0 ? std::pow(std::max(g.n_dot_h, 0.0), m) : 0.0;
}

double phong_illumination(const Geometry& g, double emitted, double ambient, double incident, double ka, double kd,
                          double ks, double m) {
  return emitted + ambient * ka + incident * (kd * std::max(g.n_dot_l, 0.0) + ks * blinn_phong_lobe(g, m));
}

double lambert_brdf(double kd) { return kd / kPi; }

double phong_brdf(const Geometry& g, double ks, double m) {
  return lit_and_seen(g) ? ks * phong_lobe(g, m) / (kPi * g.n_dot_l) : 0.0;
}

double blinn_phong_brdf(const Geometry& g, double ks, double m) {
  return lit_and_seen(g) ? ks * blinn_phong_lobe(g, m) / (kPi * g.n_dot_l) : 0.0;
}

double blinn_phong_normalized_brdf(const Geometry& g, double ks, double m) {
  return lit_and_seen(g) ? ks * (m + 8.0) / (8.0 * kPi) * blinn_phong_lobe(g, m) : 0.0;
}

double phong_plausible_brdf(const Geometry& g, double f0, double m) {
  if (!lit_and_seen(g)) return 0.0;
  return (m + 2.0) / (8.0 * kPi) * fresnel_schlick(g.l_dot_h, f0) * blinn_phong_lobe(g, m);
}

double cook_torrance_brdf(const Geometry& g, double eta, double m) {
  if (!lit_and_seen(g)) return 0.0;
  const double f = std::isinf(eta) ? 1.0 : fresnel_cook_torrance(g.l_dot_h, eta);
  return beckmann_d(g.n_dot_h, m) * f * torrance_sparrow_g(g) / (4.0 * g.n_dot_l * g.n_dot_v);
}

double ggx_brdf(const Geometry& g, double f0, double alpha) {
  if (!lit_and_seen(g)) return 0.0;
  return ggx_d(g.n_dot_h, alpha) * smith_ggx_correlated_v(g.n_dot_l, g.n_dot_v, alpha) *
         fresnel_schlick(g.l_dot_h, f0);
}

double oren_nayar_brdf(const Geometry& g, double rho, double sigma) {
  if (!lit_and_seen(g)) return 0.0;
  const double theta_i = std::acos(std::min(g.n_dot_l, 1.0));
  const double theta_r = std::acos(std::min(g.n_dot_v, 1.0));
  // cos(φ_r − φ_i) from the projections on the tangent plane; 0 when either is along n.
  const Vec3 l_t = g.l - g.n_dot_l * g.n;
  const Vec3 v_t = g.v - g.n_dot_v * g.n;
  const double lengths = glm::length(l_t) * glm::length(v_t);
  const double cos_phi = lengths > 1e-12 ? std::clamp(glm::dot(l_t, v_t) / lengths, -1.0, 1.0) : 0.0;
  const double alpha = std::max(theta_i, theta_r), beta = std::min(theta_i, theta_r);
  const double s2 = sigma * sigma;
  const double two_beta_over_pi = 2.0 * beta / kPi;
  // As in ch. 12 (eq. 12.61 ff.): C1 uses 0.3 and the second-order term ρ/π, where Oren and
  // Nayar's paper has 0.33 and ρ²/π.
  const double c1 = 1.0 - 0.5 * s2 / (s2 + 0.3);
  double c2 = 0.45 * s2 / (s2 + 0.09) * std::sin(alpha);
  if (cos_phi < 0.0) c2 = 0.45 * s2 / (s2 + 0.09) * (std::sin(alpha) - std::pow(two_beta_over_pi, 3));
  const double c3 = 0.125 * s2 / (s2 + 0.09) * std::pow(4.0 * alpha * beta / (kPi * kPi), 2);
  const double first = c1 + cos_phi * c2 * std::tan(beta) + (1.0 - std::abs(cos_phi)) * c3 * std::tan((alpha + beta) / 2);
  const double second = 0.17 * s2 / (s2 + 0.13) * (1.0 - cos_phi * two_beta_over_pi * two_beta_over_pi);
  return rho / kPi * (first + second);
}

}  // namespace matbake::shading
