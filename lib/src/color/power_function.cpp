#include "power_function.hpp"

namespace matbake::color {

PowerFunction::PowerFunction(double exponent) : exponent_(exponent) {
  // Coefficients in long double: (c + d)^p = c^p · sum_j binom(p, j) (d / c)^j.
  const long double p = exponent;
  for (int b = 0; b < kBuckets; ++b) {
    const long double c = 1.0L + (b + 0.5L) / kBuckets;
    midpoint_[b] = double(c);
    long double term = std::pow(c, p);  // binom(p, j) · c^(p - j), starting at j = 0
    for (int j = 0; j < 5; ++j) {
      taylor_[b][j] = double(term);
      term *= (p - j) / ((j + 1) * c);
    }
  }
  for (int k = kMinExponent; k <= kMaxExponent; ++k) {
    scale_[k - kMinExponent] = double(std::exp2(p * k));
  }
}

}  // namespace matbake::color
