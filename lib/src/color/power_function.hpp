#pragma once
// x^p for x >= 0 in float64 without std::pow: x = m·2^k with m in [1, 2); 2^(p·k) comes from a
// table and m^p from a degree-4 Taylor polynomial about the midpoint of one of 64 buckets of m.
// With |d/m| <= 1/128 the truncation error is |binom(p, 5)|·128^-5 relative: 3e-13 for p = 2.4,
// 9e-13 for p = 1/2.4, about 1e-5 of a float ulp, so a float result rounded from it is the
// correctly rounded float of x^p except when x^p lies that close to a rounding boundary.
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

namespace matbake::color {

class PowerFunction {
 public:
  explicit PowerFunction(double exponent);

  double operator()(double x) const {
    const uint64_t bits = std::bit_cast<uint64_t>(x);
    const int k = int(bits >> 52) - 1023;  // sign bit is 0 for x >= 0
    if (k < kMinExponent || k > kMaxExponent) {
      // 0, subnormal doubles, values beyond any float, Inf, NaN, negatives: rare, exact anyway.
      return std::pow(x, exponent_);
    }
    const int bucket = int(bits >> (52 - kBucketBits)) & (kBuckets - 1);
    const double m = std::bit_cast<double>((bits & kMantissaMask) | kOneExponentBits);
    const double d = m - midpoint_[bucket];
    const auto& c = taylor_[bucket];
    const double m_pow = c[0] + d * (c[1] + d * (c[2] + d * (c[3] + d * c[4])));
    return m_pow * scale_[k - kMinExponent];
  }

  double exponent() const { return exponent_; }

 private:
  static constexpr int kBucketBits = 6;
  static constexpr int kBuckets = 1 << kBucketBits;
  // Covers every float input (k >= -149) and the sRGB offsets around them.
  static constexpr int kMinExponent = -160;
  static constexpr int kMaxExponent = 130;
  static constexpr uint64_t kMantissaMask = (uint64_t(1) << 52) - 1;
  static constexpr uint64_t kOneExponentBits = uint64_t(1023) << 52;

  double exponent_;
  std::array<double, kBuckets> midpoint_{};
  std::array<std::array<double, 5>, kBuckets> taylor_{};
  std::array<double, kMaxExponent - kMinExponent + 1> scale_{};
};

}  // namespace matbake::color
