// Delivered sizes: the class's scale and limits, then the rounding, never above the source.
#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>

#include "matbake/delivery.hpp"

namespace matbake::delivery {
namespace {

// One side rounded: to the nearest power of two (in ratio), to the nearest multiple of 4 (sides of
// 1 and 2 stay, as KHR_texture_basisu allows; 3 becomes 2), or to the nearest integer; never above
// `limit` (rounded down the same way) and never below 1.
int rounded_side(double side, int limit, Rounding rounding) {
  switch (rounding) {
    case Rounding::power_of_two: {
      const int ceiling = int(std::bit_floor(unsigned(limit)));
      const int lower = int(std::bit_floor(unsigned(std::max(1.0, std::floor(side)))));
      // Nearest in ratio: the upper power when side ≥ √2 × the lower one.
      const int nearest = side >= lower * std::numbers::sqrt2 ? lower * 2 : lower;
      return std::min(nearest, ceiling);
    }
    case Rounding::multiple_of_4: {
      if (limit < 4) return limit == 3 ? 2 : limit;
      if (side < 3) return side < 1.5 ? 1 : 2;
      return std::clamp(int(std::lround(side / 4)) * 4, 4, limit / 4 * 4);
    }
    case Rounding::none: break;
  }
  return std::clamp(int(std::lround(side)), 1, limit);
}

}  // namespace

Size delivered_size(Size source, const ClassOptions& options, Rounding rounding, std::optional<int> needed) {
  double w = source.width * options.scale, h = source.height * options.scale;
  int longest = 0;
  if (options.max_size > 0) longest = options.max_size;
  if (needed) longest = longest > 0 ? std::min(longest, *needed) : *needed;
  if (longest > 0 && std::max(w, h) > longest) {
    const double shrink = longest / std::max(w, h);
    w *= shrink, h *= shrink;
  }
  return {rounded_side(w, source.width, rounding), rounded_side(h, source.height, rounding)};
}

}  // namespace matbake::delivery
