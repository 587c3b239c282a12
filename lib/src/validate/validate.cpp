#include "matbake/validate.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

#include "matbake/workflow.hpp"

namespace matbake::validate {
namespace {

using materials::F0Class;

constexpr int kRowsPerBlock = 64;

// One block of rows' share of the report; blocks merge in order, so the result does not depend on
// the thread count.
// Per-channel sum and range. The hot loop stays in float: a row's sum is kept in float (rows of
// a few thousand values in [0, 1]: relative error ~1e-6 typically, 1e-4 at worst) and added to the
// double total at the end of the row.
struct Accumulator {
  std::array<double, 3> sum{};
  std::array<float, 3> row_sum{}, lo{}, hi{};
  Accumulator() {
    lo.fill(std::numeric_limits<float>::infinity());
    hi.fill(-std::numeric_limits<float>::infinity());
  }
  void add(const float* v) {
    for (std::size_t c = 0; c < 3; ++c) {
      row_sum[c] += v[c];
      lo[c] = std::min(lo[c], v[c]);
      hi[c] = std::max(hi[c], v[c]);
    }
  }
  void end_row() {
    for (std::size_t c = 0; c < 3; ++c) sum[c] += row_sum[c], row_sum[c] = 0;
  }
  void merge(const Accumulator& other) {
    for (std::size_t c = 0; c < 3; ++c) {
      sum[c] += other.sum[c];
      lo[c] = std::min(lo[c], other.lo[c]);
      hi[c] = std::max(hi[c], other.hi[c]);
    }
  }
};

struct Partial {
  std::size_t masked = 0, checked = 0, violations = 0, material_within = 0;
  std::array<std::size_t, 5> class_counts{};
  std::array<std::size_t, kFlagCount> flag_counts{};
  Accumulator f0, diffuse;
  std::vector<Texel> worst;
};

bool more_severe(const Texel& a, const Texel& b) {
  if (a.severity != b.severity) return a.severity > b.severity;
  return a.y != b.y ? a.y < b.y : a.x < b.x;
}

void keep_worst(std::vector<Texel>& worst, const Texel& t, std::size_t count) {
  if (count == 0) return;
  if (worst.size() == count && !more_severe(t, worst.back())) return;
  worst.insert(std::upper_bound(worst.begin(), worst.end(), t, more_severe), t);
  if (worst.size() > count) worst.pop_back();
}

// std::min({a, b, c}) goes through min_element: a quarter of the loop's time in a profile.
float min3(const float* v) { return std::min(v[0], std::min(v[1], v[2])); }
float max3(const float* v) { return std::max(v[0], std::max(v[1], v[2])); }

void check_rows(const Inputs& in, const Options& options, int y0, int y1, Partial& p, std::uint8_t* class_map) {
  const int width = in.specular->width;
  const materials::Material* material = options.material;
  // Counters and sums live in locals, not in `p`: the byte stores to class_map may alias anything
  // reachable through `p`, which would keep them in memory.
  const float* const specular = in.specular->pixels.data();
  const float* const diffuse = in.diffuse ? in.diffuse->pixels.data() : nullptr;
  const float* const mask = in.mask ? in.mask->pixels.data() : nullptr;
  std::size_t masked = 0, checked = 0, violations = 0, material_within = 0;
  std::array<std::size_t, 5> class_counts{};
  std::array<std::size_t, kFlagCount> flag_counts{};
  Accumulator f0_stats, diffuse_stats;
  // Class boundaries on the channel sum (3 × the mean's), in float like the rest of the loop.
  const float t0 = float(3 * materials::kBelowReal), t1 = float(3 * materials::kGemFrom),
              t2 = float(3 * materials::kSemiconductorFrom), t3 = float(3 * materials::kMetalFrom);
  // The material's F0 and allowed deviation per channel.
  std::array<float, 3> reference{}, allowed{};
  for (int c = 0; c < 3 && material; ++c) {
    reference[std::size_t(c)] = float(material->f0[c]);
    allowed[std::size_t(c)] = float(options.tolerance * material->f0[c]);
  }
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      if (mask && mask[i] <= 0.0f) {
        ++masked;
        if (class_map) class_map[i] = kMaskedTexel;
        continue;
      }
      ++checked;
      const float* s = &specular[i * 3];
      const float lo = min3(s), hi = max3(s);
      const float sum = s[0] + s[1] + s[2];
      const double mean = double(sum) / 3;  // only on the (rare) flagged path
      const F0Class cls = F0Class(int(sum >= t0) + int(sum >= t1) + int(sum >= t2) + int(sum >= t3));
      ++class_counts[std::size_t(cls)];
      f0_stats.add(s);
      std::uint8_t flags = 0;
      double severity = 0;
      const auto flag = [&](Flag f, double how_far) {
        flags |= f;
        severity = std::max(severity, how_far);
      };
      if (cls == F0Class::below) flag(kBelowReal, materials::kBelowReal - mean);
      if (cls == F0Class::semiconductor) {
        flag(kSemiconductorGap, std::min(mean - materials::kSemiconductorFrom, materials::kMetalFrom - mean));
      }
      if (lo < 0 || hi > 1) flag(kNotReflectance, std::max(-lo, hi - 1.0f));
      if ((cls == F0Class::dielectric || cls == F0Class::gem) && hi - lo > float(kColouredRatio) * hi) {
        flag(kColouredDielectric, hi - lo);
      }
      const float* d = diffuse ? &diffuse[i * 3] : nullptr;
      if (d) {
        diffuse_stats.add(d);
        const float luminance = 0.2126f * d[0] + 0.7152f * d[1] + 0.0722f * d[2];
        const float d_lo = min3(d), d_hi = max3(d);
        if (d_lo < 0 || d_hi > 1) flag(kNotReflectance, std::max(-d_lo, d_hi - 1.0f));
        if (cls == F0Class::metal) {
          if (luminance >= float(kMetalDiffuseMax)) flag(kMetalWithDiffuse, luminance);
        } else if (luminance < float(kAlbedoMin) || luminance > float(kAlbedoMax)) {
          flag(kAlbedoOutOfRange, luminance < float(kAlbedoMin) ? kAlbedoMin - luminance : luminance - kAlbedoMax);
        }
      }
      if (material) {
        const bool within = std::abs(s[0] - reference[0]) <= allowed[0] && std::abs(s[1] - reference[1]) <= allowed[1] &&
                            std::abs(s[2] - reference[2]) <= allowed[2];
        if (within) {
          ++material_within;
        } else {
          flag(kMaterialMismatch, std::max({std::abs(s[0] - reference[0]), std::abs(s[1] - reference[1]),
                                            std::abs(s[2] - reference[2])}));
        }
      }
      if (class_map) class_map[i] = std::uint8_t(std::uint8_t(cls) | (flags ? kFlaggedTexel : 0));
      if (!flags) continue;
      ++violations;
      for (int bit = 0; bit < kFlagCount; ++bit) flag_counts[std::size_t(bit)] += (flags >> bit) & 1;
      if (p.worst.size() < options.worst_count || severity >= p.worst.back().severity) {
        Texel t{x, y, cls, flags, severity, Vec3(s[0], s[1], s[2]), d ? Vec3(d[0], d[1], d[2]) : Vec3(0)};
        keep_worst(p.worst, t, options.worst_count);
      }
    }
    f0_stats.end_row();
    diffuse_stats.end_row();
  }
  p.masked = masked;
  p.checked = checked;
  p.violations = violations;
  p.material_within = material_within;
  p.class_counts = class_counts;
  p.flag_counts = flag_counts;
  p.f0 = f0_stats;
  p.diffuse = diffuse_stats;
}

ChannelStats stats(double sum, double lo, double hi, std::size_t n) {
  return n ? ChannelStats{lo, hi, sum / double(n)} : ChannelStats{};
}

Status check_size(const image::Image* map, const image::Image& specular, int channels, const char* what) {
  if (!map) return success();
  if (map->width != specular.width || map->height != specular.height) {
    return Error{"", std::string(what) + " is " + std::to_string(map->width) + "x" + std::to_string(map->height) +
                         ", the specular map " + std::to_string(specular.width) + "x" + std::to_string(specular.height)};
  }
  if (map->channels != channels) return Error{"", std::string(what) + ": " + std::to_string(channels) + " channels expected"};
  return success();
}

}  // namespace

std::string_view flag_name(int bit) {
  static constexpr std::string_view kNames[kFlagCount] = {
      "below_real", "semiconductor_gap", "metal_with_diffuse", "coloured_dielectric",
      "albedo_out_of_range", "not_a_reflectance", "material_mismatch"};
  return bit >= 0 && bit < kFlagCount ? kNames[bit] : "";
}

Result<Report> validate(const Inputs& in, const Options& options) {
  if (!in.specular) return Error{"", "validation needs a specular map", true};
  if (Status s = check_size(in.specular, *in.specular, 3, "the specular map"); !s) return s.error();
  if (Status s = check_size(in.diffuse, *in.specular, 3, "the diffuse map"); !s) return s.error();
  if (Status s = check_size(in.mask, *in.specular, 1, "the mask"); !s) return s.error();
  Report report;
  report.width = in.specular->width;
  report.height = in.specular->height;
  report.texels = std::size_t(report.width) * std::size_t(report.height);
  if (options.class_map) report.class_map.assign(report.texels, 0);
  const int blocks = (report.height + kRowsPerBlock - 1) / kRowsPerBlock;
  std::vector<Partial> partials(static_cast<std::size_t>(blocks));
  tbb::parallel_for(0, blocks, [&](int b) {
    check_rows(in, options, b * kRowsPerBlock, std::min(report.height, (b + 1) * kRowsPerBlock), partials[std::size_t(b)],
               options.class_map ? report.class_map.data() : nullptr);
  });
  Partial total;
  for (const Partial& p : partials) {
    total.masked += p.masked;
    total.checked += p.checked;
    total.violations += p.violations;
    total.material_within += p.material_within;
    for (std::size_t c = 0; c < 5; ++c) total.class_counts[c] += p.class_counts[c];
    for (std::size_t f = 0; f < kFlagCount; ++f) total.flag_counts[f] += p.flag_counts[f];
    total.f0.merge(p.f0);
    total.diffuse.merge(p.diffuse);
    for (const Texel& t : p.worst) keep_worst(total.worst, t, options.worst_count);
  }
  report.masked = total.masked;
  report.checked = total.checked;
  report.violations = total.violations;
  report.material_within = total.material_within;
  report.class_counts = total.class_counts;
  report.flag_counts = total.flag_counts;
  for (std::size_t c = 0; c < 3; ++c) {
    report.f0_stats[c] = stats(total.f0.sum[c], total.f0.lo[c], total.f0.hi[c], total.checked);
    if (in.diffuse) {
      report.diffuse_stats[c] = stats(total.diffuse.sum[c], total.diffuse.lo[c], total.diffuse.hi[c], total.checked);
    }
  }
  report.worst = std::move(total.worst);
  return report;
}

std::span<const LegendEntry> heatmap_legend() {
  static constexpr LegendEntry kLegend[] = {
      {"below any real material (F0 < 0.02)", {120, 0, 160}},
      {"dielectric (0.02-0.08)", {40, 170, 70}},
      {"gem (0.08-0.2)", {0, 160, 170}},
      {"semiconductor gap (0.2-0.45)", {255, 150, 0}},
      {"metal (>= 0.45)", {200, 200, 210}},
      {"masked (skipped)", {40, 40, 40}},
      {"flagged: metal with diffuse, coloured dielectric, implausible albedo, not a reflectance, material mismatch",
       {230, 20, 20}},
  };
  return kLegend;
}

image::Image heatmap(const Report& report) {
  image::Image out;
  out.width = report.width;
  out.height = report.height;
  out.channels = 3;
  out.channel_names = {"R", "G", "B"};
  out.pixels.resize(out.sample_count());
  const auto legend = heatmap_legend();
  // The legend is in 8-bit sRGB; the image is linear like every image in memory.
  std::array<std::array<float, 3>, 7> linear{};
  for (std::size_t e = 0; e < legend.size(); ++e) {
    for (int c = 0; c < 3; ++c) {
      linear[e][std::size_t(c)] = color::decode_table(color::Transfer::srgb, 8)[legend[e].srgb[std::size_t(c)]];
    }
  }
  for (std::size_t i = 0; i < report.class_map.size(); ++i) {
    const std::uint8_t v = report.class_map[i];
    const std::size_t cls = v & 0x7f;
    // Class-inherent flags (below, semiconductor gap) keep their class colour.
    const bool other_flag = (v & kFlaggedTexel) && cls != std::size_t(F0Class::below) &&
                            cls != std::size_t(F0Class::semiconductor);
    const auto& rgb = linear[other_flag ? 6 : cls];
    std::copy(rgb.begin(), rgb.end(), out.pixels.begin() + std::ptrdiff_t(i * 3));
  }
  return out;
}

Result<SpecularDiffuse> from_metal_rough(const image::Image& base, const image::Image& metallic) {
  if (base.width != metallic.width || base.height != metallic.height) {
    return Error{"", "base colour " + std::to_string(base.width) + "x" + std::to_string(base.height) + ", metallic " +
                         std::to_string(metallic.width) + "x" + std::to_string(metallic.height)};
  }
  SpecularDiffuse out{base, base};
  const std::size_t texels = std::size_t(base.width) * std::size_t(base.height);
  for (std::size_t i = 0; i < texels; ++i) {
    const double m = metallic.pixels[i * std::size_t(metallic.channels)];
    const Vec3 b(base.pixels[i * 3], base.pixels[i * 3 + 1], base.pixels[i * 3 + 2]);
    const Vec3 f0 = workflow::specular_from_metal_rough(b, m), diffuse = workflow::diffuse_from_metal_rough(b, m);
    for (int c = 0; c < 3; ++c) {
      out.specular.pixels[i * 3 + std::size_t(c)] = float(f0[c]);
      out.diffuse.pixels[i * 3 + std::size_t(c)] = float(diffuse[c]);
    }
  }
  return out;
}

}  // namespace matbake::validate
