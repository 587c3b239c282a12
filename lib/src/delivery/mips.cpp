// Resampling and mip chains. A separable filter: per output column (then row) the source texels it
// reads and their weights, computed once per axis; rows in parallel, each written by one task, so the
// result does not depend on the thread count.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "matbake/delivery.hpp"

namespace matbake::delivery {
namespace {

constexpr double kKaiserRadius = 3;  // in output texels
constexpr double kKaiserBeta = 4;

// The modified Bessel function of the first kind, order 0, by its power series (converges fast for
// the arguments the window takes, |x| ≤ β).
double bessel_i0(double x) {
  double sum = 1, term = 1;
  for (int k = 1; term > 1e-17 * sum; ++k) {
    term *= (x / (2 * k)) * (x / (2 * k));
    sum += term;
  }
  return sum;
}

}  // namespace

double kaiser_weight(double x) {
  if (std::abs(x) >= kKaiserRadius) return 0;
  const double t = x / kKaiserRadius;
  const double window = bessel_i0(kKaiserBeta * std::sqrt(1 - t * t)) / bessel_i0(kKaiserBeta);
  const double px = std::numbers::pi * x;
  return (x == 0 ? 1 : std::sin(px) / px) * window;
}

namespace {


struct Tap {
  int index;
  float weight;
};

// For each output coordinate of an axis, its taps: taps[first[x]] .. taps[first[x + 1]).
struct Axis {
  std::vector<std::size_t> first;
  std::vector<Tap> taps;
};

Axis axis_taps(int source, int target, Filter filter, Wrap wrap) {
  Axis axis;
  const double step = double(source) / target;     // source texels per output texel
  const double footprint = std::max(1.0, step);  // the filter's unit: an output texel when shrinking
  axis.first.push_back(0);
  std::vector<std::pair<int, double>> raw;
  for (int x = 0; x < target; ++x) {
    const double centre = (x + 0.5) * step;  // in source coordinates: texel i spans [i, i + 1)
    raw.clear();
    if (filter == Filter::box) {
      const double lo = centre - footprint / 2, hi = centre + footprint / 2;
      for (int i = int(std::floor(lo)); i < int(std::ceil(hi)); ++i) {
        const double overlap = std::min(hi, i + 1.0) - std::max(lo, double(i));
        if (overlap > 0) raw.emplace_back(i, overlap);
      }
    } else {
      const double reach = kKaiserRadius * footprint;
      for (int i = int(std::floor(centre - reach)); i <= int(std::ceil(centre + reach)); ++i) {
        const double w = kaiser_weight((i + 0.5 - centre) / footprint);
        if (w != 0) raw.emplace_back(i, w);
      }
    }
    double sum = 0;
    for (const auto& [i, w] : raw) sum += w;
    for (const auto& [i, w] : raw) axis.taps.push_back({int(wrapped_index(i, source, wrap)), float(w / sum)});
    axis.first.push_back(axis.taps.size());
  }
  return axis;
}

// The 8-bit code a linear alpha is stored as: round(a · 255), clamped.
int alpha_code(float a) { return int(std::lround(std::clamp(a, 0.0f, 1.0f) * 255.0f)); }
// The smallest code a MASK material renders opaque: code / 255 ≥ cutoff.
int opaque_code(float cutoff) { return int(std::ceil(double(cutoff) * 255.0 - 1e-9)); }

void renormalise_normals(image::Image& im) {
  const std::size_t pixels = std::size_t(im.width) * std::size_t(im.height), ch = std::size_t(im.channels);
  for (std::size_t p = 0; p < pixels; ++p) renormalise_normal(&im.pixels[p * ch]);
}

// Scales the level's alpha so that as many texels as `target` × texels render opaque: the
// round(target · n) largest alphas reach the opaque code. Texels of equal alpha pass together, so
// where the wanted-th largest alpha is shared, the nearer of the counts with and without them.
void keep_coverage(image::Image& level, float cutoff, double target) {
  const int a = level.alpha_channel;
  const std::size_t pixels = std::size_t(level.width) * std::size_t(level.height), ch = std::size_t(level.channels);
  const int opaque = opaque_code(cutoff);
  if (a < 0 || opaque <= 0 || opaque > 255 || pixels == 0) return;
  std::vector<float> alphas(pixels);
  for (std::size_t p = 0; p < pixels; ++p) alphas[p] = level.pixels[p * ch + std::size_t(a)];
  const auto wanted = std::size_t(std::llround(target * double(pixels)));
  double scale = 1;
  if (wanted == 0) {
    const float largest = *std::max_element(alphas.begin(), alphas.end());
    // Every alpha below the opaque code's lower edge, (opaque − 0.5) / 255.
    if (largest > 0) scale = std::min(1.0, (opaque - 0.5) / 255.0 / largest * (1 - 1e-6));
  } else {
    std::nth_element(alphas.begin(), alphas.begin() + std::ptrdiff_t(wanted - 1), alphas.end(), std::greater<>());
    float nth = alphas[wanted - 1];  // the wanted-th largest alpha
    if (nth <= 0) return;           // fewer texels than wanted have any alpha: as high as it gets
    std::size_t with_ties = 0, above = 0;
    float next_up = 2;  // the smallest alpha above nth
    for (float v : alphas) {
      with_ties += v >= nth;
      above += v > nth;
      if (v > nth) next_up = std::min(next_up, v);
    }
    if (with_ties - wanted > wanted - above && above > 0) nth = next_up;
    scale = (opaque - 0.5) / 255.0 / nth * (1 + 1e-6);
  }
  for (std::size_t p = 0; p < pixels; ++p) {
    float& v = level.pixels[p * ch + std::size_t(a)];
    v = std::min(1.0f, float(v * scale));
  }
}

}  // namespace


std::vector<Size> mip_sizes(Size base) {
  std::vector<Size> sizes{base};
  while (sizes.back().width > 1 || sizes.back().height > 1) {
    sizes.push_back({std::max(1, sizes.back().width / 2), std::max(1, sizes.back().height / 2)});
  }
  return sizes;
}

image::Image resample(const image::Image& in, Size size, const Sampling& sampling) {
  if (in.width == size.width && in.height == size.height) return in;
  const Axis columns = axis_taps(in.width, size.width, sampling.filter, sampling.wrap_s);
  const Axis rows = axis_taps(in.height, size.height, sampling.filter, sampling.wrap_t);
  const std::size_t ch = std::size_t(in.channels);
  const std::size_t source_row = std::size_t(in.width) * ch;
  image::Image out;
  static_cast<image::ImageLayout&>(out) = in;
  out.width = size.width, out.height = size.height;
  image::reserve_pixels(out.pixels, out.sample_count());
  out.pixels.assign(out.sample_count(), 0.0f);
  // Each output row through one source row's worth of buffer, not a second image. Rows first, over
  // whole source rows: the pass that reads every source texel (6 per output texel and tap span) is
  // then a sum of contiguous rows, which the compiler vectorises; the columns' pass reads only the
  // row made.
  tbb::parallel_for(tbb::blocked_range<int>(0, size.height, 16), [&](const tbb::blocked_range<int>& band) {
    std::vector<float> down(source_row);
    for (int y = band.begin(); y < band.end(); ++y) {
      std::fill(down.begin(), down.end(), 0.0f);
      for (std::size_t t = rows.first[std::size_t(y)]; t < rows.first[std::size_t(y) + 1]; ++t) {
        const float* src = &in.pixels[std::size_t(rows.taps[t].index) * source_row];
        const float w = rows.taps[t].weight;
        for (std::size_t i = 0; i < source_row; ++i) down[i] += w * src[i];
      }
      float* texels = &out.pixels[std::size_t(y) * std::size_t(size.width) * ch];
      for (int x = 0; x < size.width; ++x) {
        for (std::size_t t = columns.first[std::size_t(x)]; t < columns.first[std::size_t(x) + 1]; ++t) {
          const float* texel = &down[std::size_t(columns.taps[t].index) * ch];
          for (std::size_t c = 0; c < ch; ++c) texels[std::size_t(x) * ch + c] += columns.taps[t].weight * texel[c];
        }
      }
    }
  });
  return out;
}

double alpha_coverage(const image::Image& im, float cutoff) {
  const int a = im.alpha_channel;
  const std::size_t pixels = std::size_t(im.width) * std::size_t(im.height);
  if (a < 0 || pixels == 0) return 1;
  const int opaque = opaque_code(cutoff);
  std::size_t covered = 0;
  for (std::size_t p = 0; p < pixels; ++p) covered += alpha_code(im.pixels[p * std::size_t(im.channels) + std::size_t(a)]) >= opaque;
  return double(covered) / double(pixels);
}

std::vector<image::Image> mip_chain(const image::Image& source, Size base, const MipRequest& request, bool whole_chain) {
  return mip_levels(source, whole_chain ? mip_sizes(base) : std::vector<Size>{base}, request);
}

void renormalise_normal(float* t) {
  double v[3] = {2.0 * t[0] - 1, 2.0 * t[1] - 1, 2.0 * t[2] - 1};
  const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (length < 1e-12) v[0] = 0, v[1] = 0, v[2] = 1;
  else for (double& c : v) c /= length;
  for (int c = 0; c < 3; ++c) t[c] = float(0.5 * v[c] + 0.5);
}

namespace {

// The levels of `sizes`, each from the source; a level of the source's own size is the source
// itself (moved when `source` is an rvalue), renormalised like the others.
template <class Source>
std::vector<image::Image> make_levels(Source&& source, const std::vector<Size>& sizes, const MipRequest& request) {
  const bool keep = request.alpha_cutoff && request.keep_coverage;
  const float cutoff = request.alpha_cutoff.value_or(0.0f);
  const double coverage = keep ? alpha_coverage(source, cutoff) : 1.0;
  const auto finish = [&](image::Image& level, bool resized) {
    if (request.texture_class == TextureClass::normal && level.channels >= 3) renormalise_normals(level);
    if (keep && resized) keep_coverage(level, cutoff, coverage);
  };
  const Size own{source.width, source.height};
  std::vector<image::Image> levels(sizes.size());
  std::optional<std::size_t> same;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    if (sizes[i] == own && !same) {
      same = i;  // made last: the others still read the source
      continue;
    }
    levels[i] = resample(source, sizes[i], request.sampling);
    finish(levels[i], true);
  }
  if (same) {
    levels[*same] = std::forward<Source>(source);
    finish(levels[*same], false);
  }
  return levels;
}

}  // namespace

std::vector<image::Image> mip_levels(const image::Image& source, const std::vector<Size>& sizes, const MipRequest& request) {
  return make_levels(source, sizes, request);
}

std::vector<image::Image> mip_levels(image::Image&& source, const std::vector<Size>& sizes, const MipRequest& request) {
  return make_levels(std::move(source), sizes, request);
}

}  // namespace matbake::delivery
