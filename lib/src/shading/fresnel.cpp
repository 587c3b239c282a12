#include <algorithm>
#include <cmath>
#include <complex>

#include "matbake/shading.hpp"

namespace matbake::shading {

double fresnel_dielectric(double cos_i, double eta) {
  if (eta == 1.0) return 0.0;  // no interface (else grazing incidence would read as 0/0)
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  const double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;  // total internal reflection
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

double fresnel_cook_torrance(double c, double eta) {
  c = std::clamp(c, 0.0, 1.0);
  const double g2 = eta * eta + c * c - 1.0;
  if (g2 < 0.0) return 1.0;  // total internal reflection (eta < 1)
  const double g = std::sqrt(g2);
  if (g + c <= 0.0) return 0.0;  // eta = 1 at grazing: no interface, nothing reflected
  const double a = (g - c) / (g + c);
  const double b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * a * a * (1.0 + b * b);
}

double fresnel_conductor(double cos_i, double eta, double k) {
  if (k == 0.0) return fresnel_dielectric(cos_i, eta);  // also avoids 0/0 at eta = 1, grazing
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  const std::complex<double> n(eta, k);
  const std::complex<double> sin2_t = (1.0 - cos_i * cos_i) / (n * n);
  const std::complex<double> cos_t = std::sqrt(1.0 - sin2_t);
  const std::complex<double> r_parallel = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  const std::complex<double> r_perpendicular = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  return 0.5 * (std::norm(r_parallel) + std::norm(r_perpendicular));
}

double fresnel_schlick(double cos_i, double f0) {
  const double m = 1.0 - std::clamp(cos_i, 0.0, 1.0);
  const double m2 = m * m;
  return f0 + (1.0 - f0) * m2 * m2 * m;
}

double fresnel_schuler(double t, double ks) {
  const double m = 1.0 - std::clamp(t, 0.0, 1.0);
  const double m2 = m * m;
  return ks + (std::min(60.0 * ks, 1.0) - ks) * m2 * m2;
}

double ior_from_f0(double f0) {
  const double s = std::sqrt(std::clamp(f0, 0.0, 1.0));
  return (1.0 + s) / (1.0 - s);  // +Inf for f0 = 1: a perfect reflector
}

double f0_from_ior(double eta, double k) {
  return ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
}

}  // namespace matbake::shading
