#include "matbake/validate.hpp"

#include <emmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "matbake/workflow.hpp"

namespace matbake::validate {
namespace {

using material_table::F0Class;

constexpr int kRowsPerBlock = 64;

// One block of rows' share of the report; blocks merge in order, so the result does not depend on
// the thread count. Per-channel sums: float within a row (rows of a few thousand values in [0, 1]:
// relative error ~1e-6 typically, 1e-4 at worst), double across rows.
struct Accumulator {
  std::array<double, 3> sum{};
  std::array<float, 3> lo{}, hi{};
  Accumulator() {
    lo.fill(std::numeric_limits<float>::max());
    hi.fill(-std::numeric_limits<float>::max());
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

constexpr float kHuge = std::numeric_limits<float>::max();

// What is the same for every row of one validation.
struct RowSetup {
  const float* specular;
  const float* diffuse;  // or null
  const float* mask;     // or null
  const material_table::Material* material;
  // Class boundaries on the channel sum (3 × the mean's), in float like the rest of the loop.
  float t0, t1, t2, t3;
  std::array<float, 3> reference{}, allowed{};  // the material's F0 and allowed deviation per channel
};

// One row's counts and sums from the first pass.
struct RowPass {
  int live = 0;                     // texels not masked
  std::array<int, 4> at_least{};    // texels with sum ≥ t0, t1, t2, t3
  int material_within = 0;
  std::array<float, 3> f0_sum{}, f0_lo{}, f0_hi{}, d_sum{}, d_lo{}, d_hi{};
};

// --- The first pass, 4 texels at a time in SSE2 (x86-64's baseline) --------------------------------
using V = __m128;

V splat(float v) { return _mm_set1_ps(v); }
V select(V m, V a, V b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
// Lanes set in a mask. A table: x86-64's baseline has no POPCNT, and __builtin_popcount would be a
// libgcc call (a seventh of the loop's time in a profile).
int count(V m) {
  static constexpr std::uint8_t kBits[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
  return kBits[_mm_movemask_ps(m)];
}
float horizontal_sum(V v) {
  alignas(16) float f[4];
  _mm_store_ps(f, v);
  return (f[0] + f[1]) + (f[2] + f[3]);
}
float horizontal(V v, float (*op)(float, float)) {
  alignas(16) float f[4];
  _mm_store_ps(f, v);
  return op(op(f[0], f[1]), op(f[2], f[3]));
}

// Four interleaved RGB texels (12 floats) as R, G and B vectors.
struct Rgb4 {
  V r, g, b;
};
Rgb4 load_rgb4(const float* p) {
  const V a0 = _mm_loadu_ps(p), a1 = _mm_loadu_ps(p + 4), a2 = _mm_loadu_ps(p + 8);  // r0g0b0r1 g1b1r2g2 b2r3g3b3
  const V r23 = _mm_shuffle_ps(a1, a2, _MM_SHUFFLE(1, 0, 3, 2));                       // r2 g2 b2 r3
  const V g01 = _mm_shuffle_ps(a0, a1, _MM_SHUFFLE(0, 0, 1, 1)), g23 = _mm_shuffle_ps(a1, a2, _MM_SHUFFLE(2, 2, 3, 3));
  const V b01 = _mm_shuffle_ps(a0, a1, _MM_SHUFFLE(1, 1, 2, 2)), b23 = _mm_shuffle_ps(a2, a2, _MM_SHUFFLE(3, 3, 0, 0));
  return {_mm_shuffle_ps(a0, r23, _MM_SHUFFLE(3, 0, 3, 0)), _mm_shuffle_ps(g01, g23, _MM_SHUFFLE(2, 0, 2, 0)),
          _mm_shuffle_ps(b01, b23, _MM_SHUFFLE(2, 0, 2, 0))};
}

struct ChannelAccumulator {
  V sum[3] = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()};
  V lo[3] = {splat(kHuge), splat(kHuge), splat(kHuge)}, hi[3] = {splat(-kHuge), splat(-kHuge), splat(-kHuge)};
  void add(const Rgb4& c, V live) {
    const V v[3] = {c.r, c.g, c.b};
    for (int k = 0; k < 3; ++k) {
      sum[k] = _mm_add_ps(sum[k], _mm_and_ps(live, v[k]));
      lo[k] = _mm_min_ps(lo[k], select(live, v[k], splat(kHuge)));
      hi[k] = _mm_max_ps(hi[k], select(live, v[k], splat(-kHuge)));
    }
  }
  void store(std::array<float, 3>& s, std::array<float, 3>& l, std::array<float, 3>& h) const {
    for (std::size_t k = 0; k < 3; ++k) {
      s[k] = horizontal_sum(sum[k]);
      l[k] = horizontal(lo[k], [](float a, float b) { return std::min(a, b); });
      h[k] = horizontal(hi[k], [](float a, float b) { return std::max(a, b); });
    }
  }
};

V min3(const Rgb4& c) { return _mm_min_ps(c.r, _mm_min_ps(c.g, c.b)); }
V max3(const Rgb4& c) { return _mm_max_ps(c.r, _mm_max_ps(c.g, c.b)); }
V abs(V v) { return _mm_andnot_ps(splat(-0.0f), v); }

// The first pass over a row: classes, counts, sums and ranges of every texel, and whether anything
// about it could be flagged (suspect); the second pass looks closer at those only. The row's last
// texels (width not a multiple of 4) are copied into a padded block whose extra texels are masked.
template <bool kMask, bool kDiffuse, bool kMaterial>
void first_pass(const RowSetup& r, std::size_t row, int width, std::uint8_t* classes, std::uint8_t* suspect, RowPass& out) {
  const V all = _mm_castsi128_ps(_mm_set1_epi32(-1));
  const V t0 = splat(r.t0), t1 = splat(r.t1), t2 = splat(r.t2), t3 = splat(r.t3);
  ChannelAccumulator f0, diffuse;
  int live_count = 0, at_least[4] = {}, within_count = 0;
  const auto block = [&](const float* s, const float* d, V live, std::uint8_t* cls_out,
                         std::uint8_t* suspect_out) __attribute__((always_inline)) {
    const Rgb4 f = load_rgb4(s);
    const V sum = _mm_add_ps(_mm_add_ps(f.r, f.g), f.b), lo = min3(f), hi = max3(f);
    const V g0 = _mm_cmpge_ps(sum, t0), g1 = _mm_cmpge_ps(sum, t1), g2 = _mm_cmpge_ps(sum, t2), g3 = _mm_cmpge_ps(sum, t3);
    const V zero = _mm_setzero_ps(), one = splat(1.0f);
    V flagged = _mm_or_ps(_mm_andnot_ps(g0, all), _mm_andnot_ps(g3, g2));  // below; semiconductor gap
    flagged = _mm_or_ps(flagged, _mm_or_ps(_mm_cmplt_ps(lo, zero), _mm_cmpgt_ps(hi, one)));
    const V coloured = _mm_cmpgt_ps(_mm_sub_ps(hi, lo), _mm_mul_ps(splat(float(kColouredRatio)), hi));
    flagged = _mm_or_ps(flagged, _mm_and_ps(_mm_andnot_ps(g2, g0), coloured));  // dielectric or gem
    live_count += count(live);
    at_least[0] += count(_mm_and_ps(live, g0)), at_least[1] += count(_mm_and_ps(live, g1));
    at_least[2] += count(_mm_and_ps(live, g2)), at_least[3] += count(_mm_and_ps(live, g3));
    f0.add(f, live);
    if constexpr (kDiffuse) {
      const Rgb4 c = load_rgb4(d);
      const V luminance = _mm_add_ps(_mm_add_ps(_mm_mul_ps(splat(0.2126f), c.r), _mm_mul_ps(splat(0.7152f), c.g)),
                                     _mm_mul_ps(splat(0.0722f), c.b));
      flagged = _mm_or_ps(flagged, _mm_or_ps(_mm_cmplt_ps(min3(c), zero), _mm_cmpgt_ps(max3(c), one)));
      flagged = _mm_or_ps(flagged, _mm_and_ps(g3, _mm_cmpge_ps(luminance, splat(float(kMetalDiffuseMax)))));
      const V implausible = _mm_or_ps(_mm_cmplt_ps(luminance, splat(float(kAlbedoMin))),
                                      _mm_cmpgt_ps(luminance, splat(float(kAlbedoMax))));
      flagged = _mm_or_ps(flagged, _mm_and_ps(_mm_andnot_ps(g2, g0), implausible));  // dielectric or gem
      diffuse.add(c, live);
    }
    if constexpr (kMaterial) {
      const V within = _mm_and_ps(
          _mm_cmple_ps(abs(_mm_sub_ps(f.r, splat(r.reference[0]))), splat(r.allowed[0])),
          _mm_and_ps(_mm_cmple_ps(abs(_mm_sub_ps(f.g, splat(r.reference[1]))), splat(r.allowed[1])),
                     _mm_cmple_ps(abs(_mm_sub_ps(f.b, splat(r.reference[2]))), splat(r.allowed[2]))));
      within_count += count(_mm_and_ps(live, within));
      flagged = _mm_or_ps(flagged, _mm_andnot_ps(within, all));
    }
    // Class 0–4 (the masks are −1 where true), kMaskedTexel where not live.
    const __m128i cls = _mm_sub_epi32(_mm_setzero_si128(),
                                      _mm_add_epi32(_mm_add_epi32(_mm_castps_si128(g0), _mm_castps_si128(g1)),
                                                    _mm_add_epi32(_mm_castps_si128(g2), _mm_castps_si128(g3))));
    const __m128i masked = _mm_set1_epi32(kMaskedTexel);
    const __m128i chosen = _mm_or_si128(_mm_and_si128(_mm_castps_si128(live), cls), _mm_andnot_si128(_mm_castps_si128(live), masked));
    const int bytes = _mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(chosen, chosen), _mm_setzero_si128()));
    std::memcpy(cls_out, &bytes, 4);
    const int bits = _mm_movemask_ps(_mm_and_ps(live, flagged));
    for (int k = 0; k < 4; ++k) suspect_out[k] = std::uint8_t((bits >> k) & 1);
  };
  const auto live_of = [&](std::size_t i) { return kMask ? _mm_cmpgt_ps(_mm_loadu_ps(r.mask + i), _mm_setzero_ps()) : all; };
  int x = 0;
  for (; x + 4 <= width; x += 4) {
    const std::size_t i = row + std::size_t(x);
    block(r.specular + i * 3, kDiffuse ? r.diffuse + i * 3 : nullptr, live_of(i), classes + x, suspect + x);
  }
  if (x < width) {
    const int n = width - x;
    const std::size_t i = row + std::size_t(x);
    float s[12] = {}, d[12] = {}, m[4] = {};
    std::uint8_t cls_tail[4], suspect_tail[4];
    std::copy_n(r.specular + i * 3, n * 3, s);
    if (kDiffuse) std::copy_n(r.diffuse + i * 3, n * 3, d);
    for (int k = 0; k < n; ++k) m[k] = kMask ? r.mask[i + std::size_t(k)] : 1.0f;
    block(s, d, _mm_cmpgt_ps(_mm_loadu_ps(m), _mm_setzero_ps()), cls_tail, suspect_tail);
    std::copy_n(cls_tail, n, classes + x);
    std::copy_n(suspect_tail, n, suspect + x);
  }
  out.live += live_count;
  for (std::size_t k = 0; k < 4; ++k) out.at_least[k] += at_least[k];
  out.material_within += within_count;
  f0.store(out.f0_sum, out.f0_lo, out.f0_hi);
  diffuse.store(out.d_sum, out.d_lo, out.d_hi);
}

using FirstPass = void (*)(const RowSetup&, std::size_t, int, std::uint8_t*, std::uint8_t*, RowPass&);

FirstPass first_pass_for(bool mask, bool diffuse, bool material) {
  static constexpr FirstPass kPasses[8] = {
      first_pass<false, false, false>, first_pass<false, false, true>, first_pass<false, true, false>,
      first_pass<false, true, true>,   first_pass<true, false, false>,  first_pass<true, false, true>,
      first_pass<true, true, false>,   first_pass<true, true, true>};
  return kPasses[int(mask) * 4 + int(diffuse) * 2 + int(material)];
}

// The second pass, for a suspect texel: its flags and how far off it is (the most of any flag).
std::uint8_t check_texel(const RowSetup& r, std::size_t i, F0Class cls, double& severity) {
  const float* s = r.specular + i * 3;
  const float lo = min3(s), hi = max3(s);
  const double mean = double(s[0] + s[1] + s[2]) / 3;
  std::uint8_t flags = 0;
  severity = 0;
  const auto flag = [&](Flag f, double how_far) {
    flags |= f;
    severity = std::max(severity, how_far);
  };
  if (cls == F0Class::below) flag(kBelowReal, material_table::kBelowReal - mean);
  if (cls == F0Class::semiconductor) {
    flag(kSemiconductorGap, std::min(mean - material_table::kSemiconductorFrom, material_table::kMetalFrom - mean));
  }
  if (lo < 0 || hi > 1) flag(kNotReflectance, std::max(-lo, hi - 1.0f));
  if ((cls == F0Class::dielectric || cls == F0Class::gem) && hi - lo > float(kColouredRatio) * hi) {
    flag(kColouredDielectric, hi - lo);
  }
  if (r.diffuse) {
    const float* d = r.diffuse + i * 3;
    const float luminance = 0.2126f * d[0] + 0.7152f * d[1] + 0.0722f * d[2];
    const float d_lo = min3(d), d_hi = max3(d);
    if (d_lo < 0 || d_hi > 1) flag(kNotReflectance, std::max(-d_lo, d_hi - 1.0f));
    // The albedo bounds are a dielectric's (or gem's): a texel below any real F0 or in the
    // semiconductor gap is flagged for that already, its diffuse colour no second cause.
    if (cls == F0Class::metal) {
      if (luminance >= float(kMetalDiffuseMax)) flag(kMetalWithDiffuse, luminance);
    } else if ((cls == F0Class::dielectric || cls == F0Class::gem) &&
               (luminance < float(kAlbedoMin) || luminance > float(kAlbedoMax))) {
      flag(kAlbedoOutOfRange, luminance < float(kAlbedoMin) ? kAlbedoMin - luminance : luminance - kAlbedoMax);
    }
  }
  if (r.material) {
    const float off[3] = {std::abs(s[0] - r.reference[0]), std::abs(s[1] - r.reference[1]), std::abs(s[2] - r.reference[2])};
    if (off[0] > r.allowed[0] || off[1] > r.allowed[1] || off[2] > r.allowed[2]) flag(kMaterialMismatch, max3(off));
  }
  return flags;
}

void check_rows(const Inputs& in, const Options& options, int y0, int y1, Partial& p, std::uint8_t* class_map) {
  const int width = in.specular->width;
  RowSetup r{in.specular->pixels.data(), in.diffuse ? in.diffuse->pixels.data() : nullptr,
             in.mask ? in.mask->pixels.data() : nullptr, options.material,
             float(3 * material_table::kBelowReal), float(3 * material_table::kGemFrom), float(3 * material_table::kSemiconductorFrom),
             float(3 * material_table::kMetalFrom)};
  for (int c = 0; c < 3 && r.material; ++c) {
    r.reference[std::size_t(c)] = float(r.material->f0[c]);
    r.allowed[std::size_t(c)] = float(options.tolerance * r.material->f0[c]);
  }
  const FirstPass pass = first_pass_for(r.mask != nullptr, r.diffuse != nullptr, r.material != nullptr);
  std::vector<std::uint8_t> classes(static_cast<std::size_t>(width)), suspect(static_cast<std::size_t>(width));
  RowPass counts;
  for (int y = y0; y < y1; ++y) {
    const std::size_t row = std::size_t(y) * std::size_t(width);
    RowPass sums;
    pass(r, row, width, classes.data(), suspect.data(), sums);
    counts.live += sums.live;
    for (std::size_t k = 0; k < 4; ++k) counts.at_least[k] += sums.at_least[k];
    counts.material_within += sums.material_within;
    for (std::size_t c = 0; c < 3; ++c) {
      p.f0.sum[c] += sums.f0_sum[c], p.diffuse.sum[c] += sums.d_sum[c];
      p.f0.lo[c] = std::min(p.f0.lo[c], sums.f0_lo[c]), p.f0.hi[c] = std::max(p.f0.hi[c], sums.f0_hi[c]);
      p.diffuse.lo[c] = std::min(p.diffuse.lo[c], sums.d_lo[c]), p.diffuse.hi[c] = std::max(p.diffuse.hi[c], sums.d_hi[c]);
    }
    for (int x = 0; x < width; ++x) {
      if (!suspect[std::size_t(x)]) continue;
      const std::size_t i = row + std::size_t(x);
      const auto cls = F0Class(classes[std::size_t(x)]);
      double severity = 0;
      const std::uint8_t flags = check_texel(r, i, cls, severity);
      if (!flags) continue;  // the first pass's float arithmetic can differ at a boundary
      classes[std::size_t(x)] = std::uint8_t(classes[std::size_t(x)] | kFlaggedTexel);
      ++p.violations;
      for (int bit = 0; bit < kFlagCount; ++bit) p.flag_counts[std::size_t(bit)] += (flags >> bit) & 1;
      // Texels come in (y, x) order and ties rank the earlier first: an equal severity never enters.
      if (p.worst.size() < options.worst_count || severity > p.worst.back().severity) {
        const float* s = r.specular + i * 3;
        const float* d = r.diffuse ? r.diffuse + i * 3 : nullptr;
        Texel t{x, y, cls, flags, severity, Vec3(s[0], s[1], s[2]), d ? Vec3(d[0], d[1], d[2]) : Vec3(0)};
        keep_worst(p.worst, t, options.worst_count);
      }
    }
    if (class_map) std::copy(classes.begin(), classes.end(), class_map + row);
  }
  p.checked = std::size_t(counts.live);
  p.masked = std::size_t(y1 - y0) * std::size_t(width) - p.checked;
  p.material_within = std::size_t(counts.material_within);
  p.class_counts = {std::size_t(counts.live - counts.at_least[0]), std::size_t(counts.at_least[0] - counts.at_least[1]),
                    std::size_t(counts.at_least[1] - counts.at_least[2]), std::size_t(counts.at_least[2] - counts.at_least[3]),
                    std::size_t(counts.at_least[3])};
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

std::string_view vocabulary_name(Vocabulary vocabulary) {
  return vocabulary == Vocabulary::metal_rough ? "metal-rough" : "spec-gloss";
}

// Metal-rough maps are checked through F0 = lerp(0.04, base colour, metallic) and diffuse = base
// colour × (1 − metallic): each flag said again in the maps' own terms.
std::string_view flag_meaning(int bit, Vocabulary vocabulary) {
  static constexpr std::string_view kSpecGloss[kFlagCount] = {
      "F0 below any real material's (< 0.02)",
      "F0 in the semiconductor gap (0.2-0.45): no dielectric, no metal",
      "a metal's F0 with a diffuse colour (metals have none)",
      "a dielectric's F0 that is coloured (max - min > 20% of max)",
      "a non-metal's diffuse albedo darker than charcoal (0.02) or brighter than toothpaste (0.94)",
      "an F0 or diffuse channel outside [0, 1]",
      "F0 outside the reference material's tolerance"};
  static constexpr std::string_view kMetalRough[kFlagCount] = {
      "metallic with a base colour darker than any real material reflects (F0 < 0.02)",
      "metal base colour darker than any real metal, or metallic between 0 and 1 (F0 0.2-0.45)",
      "partly metallic: metallic between 0 and 1 leaves a metal with a diffuse colour",
      "partly metallic with a coloured base colour: a non-metal's reflection tinted",
      "non-metal base colour darker than charcoal (0.02) or brighter than toothpaste (0.94)",
      "a base colour or metallic value outside [0, 1]",
      "metal base colour outside the reference material's tolerance"};
  if (bit < 0 || bit >= kFlagCount) return "";
  return vocabulary == Vocabulary::metal_rough ? kMetalRough[bit] : kSpecGloss[bit];
}

std::string flag_names(std::uint8_t flags) {
  std::string s;
  for (int bit = 0; bit < kFlagCount; ++bit) {
    if (!(flags & (1 << bit))) continue;
    if (!s.empty()) s += ',';
    s += flag_name(bit);
  }
  return s;
}

Result<Report> validate(const Inputs& in, const Options& options) {
  return guarded("", [&]() -> Result<Report> {
    if (!in.specular) return Error{"", "validation needs a specular map", true};
    if (Status s = check_size(in.specular, *in.specular, 3, "the specular map"); !s) return s.error();
    if (Status s = check_size(in.diffuse, *in.specular, 3, "the diffuse map"); !s) return s.error();
    if (Status s = check_size(in.mask, *in.specular, 1, "the mask"); !s) return s.error();
    Report report;
    report.has_diffuse = in.diffuse != nullptr;
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
  });
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
  image::reserve_pixels(out.pixels, out.sample_count());
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
  // Shaped like the base colour; every sample is written below, so none is filled first.
  const auto shaped_like_base = [&] {
    image::Image image;
    static_cast<image::ImageLayout&>(image) = base;
    image::reserve_pixels(image.pixels, base.pixels.size());
    image.pixels.resize(base.pixels.size());
    return image;
  };
  SpecularDiffuse out{shaped_like_base(), shaped_like_base()};
  const std::size_t texels = std::size_t(base.width) * std::size_t(base.height);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, texels, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const double m = metallic.pixels[i * std::size_t(metallic.channels)];
      const Vec3 b(base.pixels[i * 3], base.pixels[i * 3 + 1], base.pixels[i * 3 + 2]);
      const Vec3 f0 = workflow::specular_from_metal_rough(b, m), diffuse = workflow::diffuse_from_metal_rough(b, m);
      for (int c = 0; c < 3; ++c) {
        out.specular.pixels[i * 3 + std::size_t(c)] = float(f0[c]);
        out.diffuse.pixels[i * 3 + std::size_t(c)] = float(diffuse[c]);
      }
    }
  });
  return out;
}

Result<Report> validate_maps(const material::Maps& maps, const Options& options) {
  Inputs inputs;
  inputs.mask = maps.find(material::kMask);
  SpecularDiffuse converted;
  if (maps.find(material::kKs)) {
    inputs.specular = maps.find(material::kKs);
    inputs.diffuse = maps.find(material::kKd);
  } else if (maps.find(material::kBaseColor) && maps.find(material::kMetallic)) {
    auto sd = from_metal_rough(*maps.find(material::kBaseColor), *maps.find(material::kMetallic));
    if (!sd) return sd.error();
    converted = std::move(*sd);
    inputs.specular = &converted.specular;
    inputs.diffuse = &converted.diffuse;
  } else {
    return Error{"", "validation needs a specular map (ks, e.g. a Schüler pair) or metal-rough maps (base_color and "
                     "metallic)", true};
  }
  auto report = validate(inputs, options);
  if (report && !maps.find(material::kKs)) report->vocabulary = Vocabulary::metal_rough;
  return report;
}

Status write_heatmap(const Report& report, const std::filesystem::path& png) {
  if (png.extension() != ".png") return Error{png.string(), "the heatmap is a .png", true};
  const image::WriteOptions options{color::Transfer::srgb, image::SampleType::u8, "", "sRGB"};
  return image::write_image(heatmap(report), png, options);
}

bool passed(const Report& report, const Options& options) {
  return report.violation_fraction() <= options.max_violations;
}

}  // namespace matbake::validate
