// Validation: class boundaries at 8-bit codes under both curves, every flag, masks, hard cases,
// determinism across thread counts, the heatmap colours and the metal-rough relation.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <random>

#include "matbake/validate.hpp"

namespace matbake::validate {
namespace {

using material_table::F0Class;

image::Image rgb_image(int width, int height, const std::vector<float>& pixels) {
  image::Image im;
  im.width = width;
  im.height = height;
  im.channels = 3;
  im.channel_names = {"R", "G", "B"};
  im.pixels = pixels;
  return im;
}

image::Image grey(const std::vector<float>& values, int channels = 3) {
  image::Image im = rgb_image(int(values.size()), 1, {});
  im.channels = channels;
  for (float v : values) im.pixels.insert(im.pixels.end(), std::size_t(channels), v);
  return im;
}

Report check(const Inputs& in, Options options = {}) {
  auto r = validate(in, options);
  EXPECT_TRUE(r) << r.error().to_string();
  return *r;
}

TEST(Validate, ClassBoundariesAtEightBitCodesUnderBothCurves) {
  for (color::Transfer t : {color::Transfer::srgb, color::Transfer::gamma22}) {
    const auto table = color::decode_table(t, 8);
    for (double boundary : {material_table::kBelowReal, material_table::kGemFrom, material_table::kSemiconductorFrom, material_table::kMetalFrom}) {
      int code = 0;
      while (table[std::size_t(code) + 1] < boundary) ++code;  // the last code below the boundary
      const image::Image f0 = grey({table[std::size_t(code)], table[std::size_t(code) + 1]});
      Options o;
      o.class_map = true;
      const Report r = check({&f0, nullptr, nullptr}, o);
      EXPECT_EQ(r.class_map[0] & 0x7f, std::uint8_t(material_table::classify_f0(boundary) ) - 1)
          << color::transfer_name(t) << " boundary " << boundary << " code " << code;
      EXPECT_EQ(r.class_map[1] & 0x7f, std::uint8_t(material_table::classify_f0(boundary)))
          << color::transfer_name(t) << " boundary " << boundary << " code " << code + 1;
    }
  }
}

TEST(Validate, EveryFlag) {
  // F0 per texel, diffuse per texel.
  const image::Image f0 = rgb_image(7, 1, {0.01f, 0.01f, 0.01f,  0.04f, 0.04f, 0.04f,  0.04f, 0.02f, 0.04f,
                                           0.3f, 0.3f, 0.3f,     0.9f, 0.8f, 0.5f,     0.04f, 0.04f, 0.04f,
                                           -0.1f, 0.5f, 1.2f});
  const image::Image kd = rgb_image(7, 1, {0.5f, 0.5f, 0.5f,  0.5f, 0.5f, 0.5f,  0.5f, 0.5f, 0.5f,
                                           0.5f, 0.5f, 0.5f,  0.3f, 0.3f, 0.3f,  0.98f, 0.98f, 0.98f,
                                           0.0f, 0.0f, 0.0f});
  Options o;
  o.class_map = true;
  const Report r = check({&f0, &kd, nullptr}, o);
  EXPECT_EQ(r.checked, 7u);
  EXPECT_EQ(r.flag_counts[0], 1u);  // below_real
  EXPECT_EQ(r.flag_counts[1], 1u);  // semiconductor_gap
  EXPECT_EQ(r.flag_counts[2], 1u);  // metal_with_diffuse
  EXPECT_EQ(r.flag_counts[3], 1u);  // coloured_dielectric (0.04, 0.02, 0.04)
  EXPECT_EQ(r.flag_counts[4], 1u);  // albedo_out_of_range (0.98)
  EXPECT_EQ(r.flag_counts[5], 1u);  // not_a_reflectance (−0.1 and 1.2)
  EXPECT_EQ(r.flag_counts[6], 0u);  // no --material
  EXPECT_EQ(r.violations, 6u);      // texel 1 is clean
  EXPECT_EQ(r.class_map[1], std::uint8_t(F0Class::dielectric));
  EXPECT_EQ(r.class_counts, (std::array<std::size_t, 5>{1, 3, 0, 1, 2}));
  // Worst first: the metal's diffuse luminance 0.3 is the largest excess.
  ASSERT_FALSE(r.worst.empty());
  EXPECT_EQ(r.worst[0].x, 4);
  EXPECT_EQ(r.worst[0].flags, kMetalWithDiffuse);
  EXPECT_NEAR(r.worst[0].severity, 0.3, 1e-6);
  EXPECT_NEAR(r.f0_stats[0].min, -0.1, 1e-6);
  EXPECT_NEAR(r.f0_stats[2].max, 1.2, 1e-6);
}

TEST(Validate, MaterialToleranceAndShareWithin) {
  const material_table::Material* gold = material_table::find(material_table::builtin_table(), "gold");
  const Vec3 g = gold->f0;
  const image::Image f0 = rgb_image(3, 1, {float(g.r), float(g.g), float(g.b),
                                           float(g.r * 1.09), float(g.g * 0.92), float(g.b),
                                           float(g.r), float(g.g), float(g.b * 1.2)});
  Options o;
  o.material = gold;
  const Report r = check({&f0, nullptr, nullptr}, o);
  EXPECT_EQ(r.material_within, 2u);
  EXPECT_EQ(r.flag_counts[6], 1u);
  EXPECT_EQ(r.worst[0].x, 2);
  o.tolerance = 0.25;
  EXPECT_EQ(check({&f0, nullptr, nullptr}, o).material_within, 3u);
}

TEST(Validate, MaskedTexelsAreSkippedAndFullyMaskedIsClean) {
  const image::Image f0 = grey({0.3f, 0.01f, 0.04f});
  const image::Image mask = grey({0.0f, 1.0f, 0.5f}, 1);
  Options o;
  o.class_map = true;
  const Report r = check({&f0, nullptr, &mask}, o);
  EXPECT_EQ(r.masked, 1u);
  EXPECT_EQ(r.checked, 2u);
  EXPECT_EQ(r.flag_counts[1], 0u);  // the semiconductor-gap texel was masked
  EXPECT_EQ(r.class_map[0], kMaskedTexel);
  const image::Image none = grey({0.0f, 0.0f, 0.0f}, 1);
  const Report all = check({&f0, nullptr, &none});
  EXPECT_EQ(all.checked, 0u);
  EXPECT_EQ(all.violation_fraction(), 0.0);
}

TEST(Validate, OneTexelAndSizeErrors) {
  const image::Image one = grey({0.04f});
  EXPECT_EQ(check({&one, nullptr, nullptr}).class_counts[1], 1u);
  const image::Image two = grey({0.5f, 0.5f});
  auto r = validate({&one, &two, nullptr}, {});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "the diffuse map is 2x1, the specular map 1x1");
  EXPECT_FALSE(validate({nullptr, nullptr, nullptr}, {}));
}

TEST(Validate, SameReportWhateverTheThreadCount) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> pixels(300 * 200 * 3);
  for (float& p : pixels) p = u(rng) * u(rng);
  const image::Image f0 = rgb_image(300, 200, pixels);
  Options o;
  o.class_map = true;
  Report one, many;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = check({&f0, nullptr, nullptr}, o);
  }
  many = check({&f0, nullptr, nullptr}, o);
  EXPECT_EQ(one.class_counts, many.class_counts);
  EXPECT_EQ(one.flag_counts, many.flag_counts);
  EXPECT_EQ(one.class_map, many.class_map);
  EXPECT_EQ(one.f0_stats[1].mean, many.f0_stats[1].mean);
  ASSERT_EQ(one.worst.size(), 10u);
  for (std::size_t i = 0; i < one.worst.size(); ++i) {
    EXPECT_EQ(one.worst[i].x, many.worst[i].x);
    EXPECT_EQ(one.worst[i].y, many.worst[i].y);
  }
}

TEST(Validate, HeatmapColoursFollowTheLegend) {
  const image::Image f0 = grey({0.01f, 0.04f, 0.1f, 0.3f, 0.9f, 0.04f});
  const image::Image mask = grey({1, 1, 1, 1, 1, 0}, 1);
  const image::Image kd = grey({0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f});  // the metal gets flagged
  Options o;
  o.class_map = true;
  const image::Image map = heatmap(check({&f0, &kd, &mask}, o));
  const auto legend = heatmap_legend();
  const std::size_t expected[] = {0, 1, 2, 3, 6, 5};
  for (std::size_t i = 0; i < 6; ++i) {
    for (std::size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(color::quantize(color::Transfer::srgb, 8, map.pixels[i * 3 + c]), legend[expected[i]].srgb[c])
          << "texel " << i;
    }
  }
}

// The first pass runs 4 texels at a time: widths that are not a multiple of 4 (the padded tail),
// masks, diffuse and a material, against the per-texel rule (classify_f0 of the mean, in float64)
// and float64 statistics.
TEST(Validate, VectorPassMatchesThePerTexelRule) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 1);
  for (const auto& [width, height] : {std::pair{37, 5}, std::pair{1, 3}, std::pair{6, 2}, std::pair{4, 4}}) {
    const std::size_t n = std::size_t(width) * std::size_t(height);
    std::vector<float> f0(n * 3), kd(n * 3), mask(n);
    for (std::size_t i = 0; i < n; ++i) {
      const float base = std::pow(u(rng), 2.5f);  // most texels dielectric-ish, some metals
      for (std::size_t c = 0; c < 3; ++c) f0[i * 3 + c] = base * (0.8f + 0.4f * u(rng));
      for (std::size_t c = 0; c < 3; ++c) kd[i * 3 + c] = u(rng);
      mask[i] = u(rng) < 0.2f ? 0.0f : 1.0f;
    }
    image::Image specular = rgb_image(width, height, f0), diffuse = rgb_image(width, height, kd);
    image::Image m = rgb_image(width, height, mask);
    m.channels = 1;
    Options options;
    options.class_map = true;
    options.material = material_table::find(material_table::builtin_table(), "gold");
    const Report r = check({&specular, &diffuse, &m}, options);
    std::array<std::size_t, 5> classes{};
    std::size_t masked = 0, flagged = 0;
    std::array<double, 3> sum{}, lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
    for (std::size_t i = 0; i < n; ++i) {
      if (mask[i] <= 0) {
        ++masked;
        EXPECT_EQ(r.class_map[i], kMaskedTexel) << i;
        continue;
      }
      const F0Class expected = material_table::classify_f0((double(f0[i * 3]) + f0[i * 3 + 1] + f0[i * 3 + 2]) / 3);
      ++classes[std::size_t(expected)];
      EXPECT_EQ(r.class_map[i] & 0x7f, std::uint8_t(expected)) << width << "x" << height << " texel " << i;
      const bool is_flagged = (r.class_map[i] & kFlaggedTexel) != 0;
      flagged += is_flagged;
      if (expected == F0Class::below || expected == F0Class::semiconductor) {
        EXPECT_TRUE(is_flagged) << i;
      }
      for (std::size_t c = 0; c < 3; ++c) {
        sum[c] += f0[i * 3 + c];
        lo[c] = std::min(lo[c], double(f0[i * 3 + c]));
        hi[c] = std::max(hi[c], double(f0[i * 3 + c]));
      }
    }
    EXPECT_EQ(r.masked, masked);
    EXPECT_EQ(r.checked, n - masked);
    EXPECT_EQ(r.class_counts, classes);
    EXPECT_EQ(r.violations, flagged);
    for (std::size_t c = 0; c < 3 && r.checked; ++c) {
      EXPECT_NEAR(r.f0_stats[c].mean, sum[c] / double(r.checked), 1e-6);
      EXPECT_EQ(r.f0_stats[c].min, lo[c]);
      EXPECT_EQ(r.f0_stats[c].max, hi[c]);
    }
  }
}

TEST(Validate, MetalRoughRelation) {
  const image::Image base = grey({1.0f, 0.5f});
  const image::Image metallic = grey({1.0f, 0.0f}, 1);
  auto sd = from_metal_rough(base, metallic);
  ASSERT_TRUE(sd);
  EXPECT_FLOAT_EQ(sd->specular.pixels[0], 1.0f);
  EXPECT_FLOAT_EQ(sd->diffuse.pixels[0], 0.0f);
  EXPECT_FLOAT_EQ(sd->specular.pixels[3], 0.04f);
  EXPECT_FLOAT_EQ(sd->diffuse.pixels[3], 0.5f);
  EXPECT_FALSE(from_metal_rough(base, grey({1.0f}, 1)));
}

}  // namespace
}  // namespace matbake::validate
