// Strauss's model (ch. 12) with his constants k_f = 1.12, k_g = 1.01, k_j = 0.1. Angles enter his
// Fresnel-like F and shadowing G normalized to [0, 1] (θ / (π/2)), as in Strauss 1990.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "matbake/shading.hpp"

namespace matbake::shading {
namespace {

constexpr double kF = 1.12, kG = 1.01, kJ = 0.1;

double strauss_f(double x) {
  const double a = 1.0 / ((x - kF) * (x - kF)) - 1.0 / (kF * kF);
  const double b = 1.0 / ((1.0 - kF) * (1.0 - kF)) - 1.0 / (kF * kF);
  return a / b;
}

double strauss_g(double x) {
  const double a = 1.0 / ((1.0 - kG) * (1.0 - kG)) - 1.0 / ((x - kG) * (x - kG));
  const double b = 1.0 / ((1.0 - kG) * (1.0 - kG)) - 1.0 / (kG * kG);
  return a / b;
}

double normalized_angle(double cosine) { return std::acos(std::clamp(cosine, 0.0, 1.0)) / (std::numbers::pi / 2); }

// s = 1 would make the highlight exponent 3/(1 − s) infinite; a smoothness this close to 1 is
// already a mirror for every purpose here.
constexpr double kMaxSmoothness = 1.0 - 1e-6;

}  // namespace

double strauss_intensity(const Geometry& g, const StraussMaterial& m) {
  if (g.n_dot_l <= 0.0 || g.n_dot_v <= 0.0) return 0.0;
  const double s = std::clamp(m.smoothness, 0.0, kMaxSmoothness);
  const double x_i = normalized_angle(g.n_dot_l), x_r = normalized_angle(g.n_dot_v);
  const double r_d = (1.0 - s * s * s) * (1.0 - m.transparency);
  const double diffuse = g.n_dot_l * r_d * (1.0 - m.metalness * s) * m.color;
  const double r_n = 1.0 - m.transparency - r_d;
  const double r_j = std::min(1.0, r_n + (r_n + kJ) * strauss_f(x_i) * strauss_g(x_i) * strauss_g(x_r));
  const double r_s = std::pow(std::max(g.r_dot_v, 0.0), 3.0 / (1.0 - s)) * r_j;
  // Specular colour: white, shifted towards the surface colour for metals away from grazing.
  const double c_s = 1.0 + m.metalness * (1.0 - strauss_f(x_i)) * (m.color - 1.0);
  return diffuse + r_s * c_s;
}

double strauss_brdf(const Geometry& g, const StraussMaterial& m) {
  if (g.n_dot_l <= 0.0) return 0.0;
  return strauss_intensity(g, m) / (std::numbers::pi * g.n_dot_l);
}

}  // namespace matbake::shading
