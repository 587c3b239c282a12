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
  const float* threshold;       // max + 1 entries; [0] unused
  const uint16_t* bucket_code;  // code of the first float of each bucket, buckets 0..1.0f
  int max;

  uint16_t code_of(float linear) const {
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

  QuantizerView view() const { return {threshold.data(), bucket_code.data(), max}; }
};

// Built on first use, once per process; bits is 8 or 16.
const Quantizer& quantizer(Transfer transfer, int bits);

}  // namespace matbake::color
