#pragma once
// quantize() without evaluating any power. threshold[k] is the smallest float x with
// quantize_reference(x) >= k (k = 1..max). The code of x is the largest k with threshold[k] <= x,
// searched only between the codes of the first floats of x's bucket and of the next bucket (a
// bucket: the floats sharing their top 16 bits, i.e. sign, exponent and 7 mantissa bits).
#include <bit>
#include <cstdint>
#include <vector>

#include "matbake/color.hpp"

namespace matbake::color {

// Plain pointers: a kernel copies this into locals, so its byte stores (which may alias anything)
// do not force the table pointers to be reloaded for every sample.
struct QuantizerView {
  static constexpr int kBucketShift = 16;
  const float* threshold;       // max + 2 entries; [0] unused, [max + 1] +Inf
  const uint16_t* bucket_code;  // code of the first float of each bucket, buckets 0..1.0f
  int max;
  bool one_step;  // no bucket spans more than one code boundary (so for every 8-bit quantizer)

  uint16_t code_of(float linear) const { return one_step ? code_of_one_step(linear) : code_of_any(linear); }

  // With one_step: a bucket's floats have its first float's code or the next one, which starts at
  // that code's threshold. No branch: clamped to [0, 1] (NaN to 0) so every float has a bucket,
  // and 1.0f's code is max, whose next threshold is +Inf.
  uint16_t code_of_one_step(float linear) const {
    const float x = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;
    const int lo = bucket_code[std::bit_cast<uint32_t>(x) >> kBucketShift];
    return uint16_t(lo + int(x >= threshold[lo + 1]));
  }

  uint16_t code_of_any(float linear) const {
    if (!(linear >= threshold[1])) return 0;  // also NaN and negatives
    if (linear >= threshold[max]) return uint16_t(max);
    // 0 < linear < 1 here, so its bucket and the next one are in the table.
    const uint32_t bucket = std::bit_cast<uint32_t>(linear) >> kBucketShift;
    int lo = bucket_code[bucket], hi = bucket_code[bucket + 1];
    if (hi - lo <= 1) {
      // Nearly always so for 8 bits: one comparison, without a branch to mispredict.
      return uint16_t(lo + int(hi > lo && linear >= threshold[hi]));
    }
    while (lo < hi) {
      const int mid = (lo + hi + 1) / 2;
      if (linear >= threshold[mid]) lo = mid;
      else hi = mid - 1;
    }
    return uint16_t(lo);
  }
};

struct Quantizer {
  int max = 0;
  std::vector<float> threshold;
  std::vector<uint16_t> bucket_code;
  bool one_step = false;

  QuantizerView view() const { return {threshold.data(), bucket_code.data(), max, one_step}; }
};

// Built on first use, once per process; bits is 8 or 16.
const Quantizer& quantizer(Transfer transfer, int bits);

}  // namespace matbake::color
