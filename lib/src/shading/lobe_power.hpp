#pragma once
// x^e for the specular lobes (x = n·h or r·v in [0, 1], e = 2^(12 g) up to 4096) and 2^y, without
// libm: libm's pow (a log and an exp, about 20 ns) is most of the cost of Schüler's simplified
// models on a CPU, where a GPU does both in a cycle.
//  log2(x): x = m·2^k, m in [1, 2); with c the start of m's 1/256-wide bucket and u = (m − c)/c
//           (0 ≤ u < 1/256), log2(m) = log2(c) + ln(1 + u)/ln 2, the series to u^6 (truncation
//           u^7/7 ≈ 2e-18). Bucket starts make log2 exact at powers of two, so 1^e = 1 exactly.
//  exp2(y): y = k + j/256 + r with 0 ≤ r < 1/256; 2^y = 2^k · 2^(j/256) · exp(r ln 2), the series to
//           the 5th power (truncation (ln2/256)^6/720 ≈ 5e-19).
// x^e = exp2(e · log2 x): the log's rounding (≈1e-16 absolute) is multiplied by e, so the result is
// within about e · 2e-16 relative of the exact value (tests: ≤ 1e-12 for e ≤ 4096).
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

namespace matbake::shading {

class LobePower {
 public:
  static const LobePower& instance() {
    static const LobePower tables;
    return tables;
  }

  double log2(double x) const {  // x > 0, finite
    const uint64_t bits = std::bit_cast<uint64_t>(x);
    const int k = int(bits >> 52) - 1023;
    const int j = int(bits >> (52 - kBits)) & (kSize - 1);
    const double m = std::bit_cast<double>((bits & kMantissa) | kOne);
    const double u = (m - centre_[j]) * inverse_centre_[j];
    // ln(1 + u) = u − u²/2 + u³/3 − u⁴/4 + u⁵/5 − u⁶/6
    const double ln = u * (1.0 + u * (-0.5 + u * (1.0 / 3 + u * (-0.25 + u * (0.2 - u / 6)))));
    return k + log2_centre_[j] + ln * kInvLn2;
  }

  double exp2(double y) const {
    if (y < -1022.0) return 0.0;  // below the normal range: negligible for a lobe
    if (y > 1023.0) return HUGE_VAL;
    // floor without libm (baseline x86-64 has no rounding instruction): truncate, then step down
    // for negative non-integers.
    int64_t k = int64_t(y);
    k -= double(k) > y;
    const double scaled = (y - double(k)) * kSize;
    const int j = int(scaled);
    const double r = (scaled - j) * (kLn2 / kSize);  // r ln 2, in [0, ln2/256)
    const double e = 1.0 + r * (1.0 + r * (0.5 + r * (1.0 / 6 + r * (1.0 / 24 + r * (1.0 / 120)))));
    const double two_k = std::bit_cast<double>(uint64_t(k + 1023) << 52);
    return two_k * power_[j] * e;
  }

  // x^e for x ≤ 1, e > 0 (0 for x ≤ 0).
  double pow(double x, double e) const { return x > 0.0 ? exp2(e * log2(x)) : 0.0; }

 private:
  static constexpr int kBits = 8;
  static constexpr int kSize = 1 << kBits;
  static constexpr uint64_t kMantissa = (uint64_t(1) << 52) - 1;
  static constexpr uint64_t kOne = uint64_t(1023) << 52;
  static constexpr double kLn2 = 0.693147180559945309417;
  static constexpr double kInvLn2 = 1.442695040888963407360;

  LobePower() {
    for (int j = 0; j < kSize; ++j) {
      const long double c = 1.0L + (long double)j / kSize;
      centre_[j] = double(c);
      inverse_centre_[j] = double(1.0L / c);
      log2_centre_[j] = double(std::log2(c));
      power_[j] = double(std::exp2((long double)j / kSize));
    }
  }

  std::array<double, kSize> centre_{}, inverse_centre_{}, log2_centre_{}, power_{};
};

}  // namespace matbake::shading
