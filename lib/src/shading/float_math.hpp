#pragma once
// exp2 and log2 in float without libm calls, so loops that use them vectorise (glibc's vector
// math is only declared under -ffast-math, which would also remove our NaN checks). Relative error
// of both below 3e-7 on their domains (tests/unit/test_shading_batch.cpp sweeps them).
#include <algorithm>
#include <bit>
#include <cstdint>

namespace matbake::shading::float_math {

// 2^x; 0 below −126 (the smallest normal float's exponent), 2^127·… clamped above.
[[gnu::always_inline]] inline float exp2(float x) {
  const float clamped = std::min(std::max(x, -126.0f), 127.0f);
  // Round to nearest integer by adding and removing 1.5·2^23 (exact for |x| < 2^22).
  const float whole = (clamped + 12582912.0f) - 12582912.0f;
  const float f = clamped - whole;  // [−0.5, 0.5]
  // 2^f = e^(f ln 2): Taylor series to degree 7, truncation error < 5e-9 for |f ln 2| ≤ 0.347.
  const float t = f * 0.693147181f;
  float p = 1.0f / 5040.0f;
  p = p * t + 1.0f / 720.0f;
  p = p * t + 1.0f / 120.0f;
  p = p * t + 1.0f / 24.0f;
  p = p * t + 1.0f / 6.0f;
  p = p * t + 0.5f;
  p = p * t + 1.0f;
  p = p * t + 1.0f;
  const float scale = std::bit_cast<float>((static_cast<std::int32_t>(whole) + 127) << 23);
  return x < -126.0f ? 0.0f : p * scale;
}

// log2(x) for normal positive x (callers keep x ≥ FLT_MIN).
[[gnu::always_inline]] inline float log2(float x) {
  const std::int32_t bits = std::bit_cast<std::int32_t>(x);
  float mantissa = std::bit_cast<float>((bits & 0x007fffff) | 0x3f800000);  // [1, 2)
  float exponent = static_cast<float>(((bits >> 23) & 0xff) - 127);
  // Fold the mantissa into [√½, √2) so that t below stays small and x near 1 keeps its relative precision.
  const bool fold = mantissa > 1.41421356f;
  mantissa = fold ? mantissa * 0.5f : mantissa;
  exponent = fold ? exponent + 1.0f : exponent;
  // ln m = 2 atanh(t), t = (m − 1)/(m + 1), |t| ≤ 0.172: odd series to t^9, error < 2e-9.
  const float t = (mantissa - 1.0f) / (mantissa + 1.0f);
  const float t2 = t * t;
  float p = 1.0f / 9.0f;
  p = p * t2 + 1.0f / 7.0f;
  p = p * t2 + 1.0f / 5.0f;
  p = p * t2 + 1.0f / 3.0f;
  p = p * t2 + 1.0f;
  return exponent + 2.885390082f * t * p;  // 2/ln 2
}

// x^y for x in [0, 1] and y ≥ 1 (the Blinn-Phong lobe); 0 below the smallest normal float.
[[gnu::always_inline]] inline float pow_unit(float x, float y) {
  return x < 1.17549435e-38f ? 0.0f : exp2(y * log2(x));
}

}  // namespace matbake::shading::float_math
