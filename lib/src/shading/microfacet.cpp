#include <algorithm>
#include <cmath>
#include <numbers>

#include "matbake/shading.hpp"

namespace matbake::shading {
namespace {
// m → 0 (or alpha → 0) is a mirror, a delta that no finite function represents; the floor keeps
// values finite (1/(π m²) ≈ 3e11) while lobes stay far narrower than any grid or texel resolves.
constexpr double kMinRoughness = 1e-6;
}  // namespace

double beckmann_d(double n_dot_h, double m) {
  if (n_dot_h <= 0.0) return 0.0;
  m = std::max(m, kMinRoughness);
  const double c2 = std::min(n_dot_h * n_dot_h, 1.0);
  // exp(−tan²/m²) underflows long before cos⁴θ does; stop before 0/0.
  if (c2 < 1e-150) return 0.0;
  const double tan2 = (1.0 - c2) / c2;
  return std::exp(-tan2 / (m * m)) / (std::numbers::pi * m * m * c2 * c2);
}

double torrance_sparrow_g(const Geometry& g) {
  if (g.n_dot_l <= 0.0 || g.n_dot_v <= 0.0) return 0.0;
  if (g.l_dot_h <= 0.0) return 1.0;  // both ratios → +∞
  const double k = 2.0 * std::max(g.n_dot_h, 0.0) / g.l_dot_h;
  return std::min({1.0, k * g.n_dot_v, k * g.n_dot_l});
}

double ggx_d(double n_dot_h, double alpha) {
  if (n_dot_h <= 0.0) return 0.0;
  alpha = std::max(alpha, kMinRoughness);
  const double a2 = alpha * alpha;
  const double d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
  return a2 / (std::numbers::pi * d * d);
}

double smith_ggx_correlated_v(double n_dot_l, double n_dot_v, double alpha) {
  if (n_dot_l <= 0.0 || n_dot_v <= 0.0) return 0.0;
  alpha = std::max(alpha, kMinRoughness);
  const double a2 = alpha * alpha;
  const double lambda_v = n_dot_l * std::sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
  const double lambda_l = n_dot_v * std::sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
  return 0.5 / (lambda_v + lambda_l);
}

}  // namespace matbake::shading
