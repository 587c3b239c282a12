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

// A KTX2 file's bytes besides its levels: the 80-byte header, 24 bytes of level index a level, a
// one-sample data format descriptor (44 bytes) and the key/value data (the writer's name: ~96 bytes).
std::uint64_t ktx2_overhead(int levels) { return 80 + 24 * std::uint64_t(levels) + 44 + 96; }

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

std::optional<int> needed_side(const std::vector<MappedTriangle>& triangles, Size source, double density) {
  const double longer = std::max(source.width, source.height);
  const double a = source.width / longer, b = source.height / longer;
  std::vector<std::pair<double, double>> sides;  // (needed L, world area)
  double total = 0;
  for (const MappedTriangle& t : triangles) {
    if (!(t.world_area > 0) || !(t.uv_area > 0) || !std::isfinite(t.world_area / t.uv_area)) continue;
    sides.emplace_back(density * std::sqrt(t.world_area / (t.uv_area * a * b)), t.world_area);
    total += t.world_area;
  }
  if (sides.empty()) return std::nullopt;
  std::sort(sides.begin(), sides.end());
  double below = 0;
  for (const auto& [side, area] : sides) {
    below += area;
    if (below >= kDensityPercentile * total) return int(std::min(1e9, std::ceil(side - 1e-9)));
  }
  return int(std::min(1e9, std::ceil(sides.back().first - 1e-9)));
}

std::uint64_t estimated_bytes(const TextureReport& planned, const ClassOptions& options) {
  const double base_texels = double(planned.delivered.width) * double(planned.delivered.height);
  const double source_texels = double(planned.source.width) * double(planned.source.height);
  if (!(source_texels > 0)) return planned.source_bytes;
  if (planned.codec == Codec::png) {
    if (planned.delivered == planned.source) return planned.source_bytes;
    return std::uint64_t(std::llround(double(planned.source_bytes) * base_texels / source_texels));
  }
  // The rates below are of the whole chain per texel of level 0; one level is 3/4 of a chain.
  const double one_level = planned.levels > 1 ? 1.0 : 0.75;
  const double source_bits = 8.0 * double(planned.source_bytes) / source_texels;
  if (planned.codec == Codec::etc1s) {
    const double bits = std::min(kEtc1sMaxBits, kEtc1sSourceShare * source_bits) * one_level;
    return ktx2_overhead(planned.levels) + std::uint64_t(std::llround(base_texels * bits / 8));
  }
  std::uint64_t blocks = 0;
  const std::vector<Size> sizes = mip_sizes(planned.delivered);
  for (std::size_t l = 0; l < std::size_t(planned.levels) && l < sizes.size(); ++l) {
    blocks += std::uint64_t((sizes[l].width + 3) / 4) * std::uint64_t((sizes[l].height + 3) / 4);
  }
  double bytes = double(blocks) * 16;  // UASTC: 16 bytes a 4 × 4 block
  if (options.zstd > 0) bytes = std::min(bytes, base_texels * (kUastcZstdFloorBits + source_bits) * one_level / 8);
  return ktx2_overhead(planned.levels) + std::uint64_t(std::llround(bytes));
}

}  // namespace matbake::delivery
