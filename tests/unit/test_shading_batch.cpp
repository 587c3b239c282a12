// The float batch path against the float64 functions on the same inputs, its exp2/log2 against
// libm, and the hard cases (g = 0 and 1, e = 4096 at n·h → 1, l·h → 0, below the horizon).
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cfloat>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "lib/src/shading/float_math.hpp"
#include "matbake/shading_batch.hpp"

namespace matbake::shading {
namespace {

constexpr SchulerVariant kVariants[] = {SchulerVariant::full, SchulerVariant::simplified,
                                        SchulerVariant::kelemen_szirmay_kalos, SchulerVariant::optimized};

TEST(FloatMath, Exp2MatchesLibmOverTheNormalRange) {
  double worst = 0;
  for (float x = -126.0f; x <= 127.0f; x += 0.0009765625f * 3.0f) {
    const double reference = std::exp2(double(x));
    worst = std::max(worst, std::abs(float_math::exp2(x) - reference) / reference);
  }
  EXPECT_LT(worst, 3e-7);
  EXPECT_EQ(float_math::exp2(-126.5f), 0.0f);
  EXPECT_EQ(float_math::exp2(-1e30f), 0.0f);
  EXPECT_EQ(float_math::exp2(0.0f), 1.0f);
  EXPECT_EQ(float_math::exp2(12.0f), 4096.0f);
}

TEST(FloatMath, Log2MatchesLibmIncludingJustBelowOne) {
  double worst = 0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> exponent(-126, 127);
  for (int i = 0; i < 200000; ++i) {
    const float x = std::exp2(exponent(rng));
    const double reference = std::log2(double(x));
    worst = std::max(worst, std::abs(float_math::log2(x) - reference) / std::max(1.0, std::abs(reference)));
  }
  EXPECT_LT(worst, 3e-7);
  // Relative accuracy near 1, where (n·h)^4096 lives.
  for (float x : {1.0f - 0x1p-24f, 1.0f - 1e-5f, 0.999f, 1.0f + 0x1p-23f}) {
    const double reference = std::log2(double(x));
    EXPECT_NEAR(float_math::log2(x), reference, 3e-7 * std::abs(reference)) << x;
  }
  EXPECT_EQ(float_math::log2(1.0f), 0.0f);
  EXPECT_EQ(float_math::pow_unit(0.0f, 1.0f), 0.0f);
  EXPECT_EQ(float_math::pow_unit(1.0f, 4096.0f), 1.0f);
}

struct Samples {
  std::vector<float> n_dot_l, n_dot_v, n_dot_h, l_dot_h, ks, gloss;
  void add(const Geometry& g, double k, double glossiness) {
    n_dot_l.push_back(float(g.n_dot_l));
    n_dot_v.push_back(float(g.n_dot_v));
    n_dot_h.push_back(float(g.n_dot_h));
    l_dot_h.push_back(float(g.l_dot_h));
    ks.push_back(float(k));
    gloss.push_back(float(glossiness));
  }
  // The float64 reference on exactly the float inputs.
  double reference(SchulerVariant variant, std::size_t i) const {
    Geometry g;
    g.n_dot_l = n_dot_l[i];
    g.n_dot_v = n_dot_v[i];
    g.n_dot_h = n_dot_h[i];
    g.l_dot_h = l_dot_h[i];
    return schuler_specular(variant, g, ks[i], gloss[i]);
  }
  std::vector<float> run(SchulerVariant variant) const {
    std::vector<float> out(ks.size());
    schuler_specular_batch(variant, {n_dot_l, n_dot_v, n_dot_h, l_dot_h, ks, gloss}, out);
    return out;
  }
};

Vec3 direction_from_cosine(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

TEST(ShadingBatch, MatchesFloat64OnRandomSamples) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  Samples s;
  for (int i = 0; i < 100000; ++i) {
    // v anywhere (also below the horizon), l near the mirror direction so the lobe is sampled.
    const Vec3 v = direction_from_cosine(2 * u(rng) - 1, 6.283 * u(rng));
    const Vec3 l = glm::normalize(Vec3(-v.x, -v.y, v.z) + 0.3 * direction_from_cosine(2 * u(rng) - 1, 6.283 * u(rng)));
    s.add(make_geometry({0, 0, 1}, l, v), 0.02 + 0.97 * u(rng), u(rng));
  }
  for (SchulerVariant variant : kVariants) {
    const std::vector<float> out = s.run(variant);
    double worst = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double reference = s.reference(variant, i);
      ASSERT_TRUE(std::isfinite(out[i]) && out[i] >= 0) << i;
      if (reference < 1e-6) {
        EXPECT_NEAR(out[i], reference, 1e-10) << i;  // below 1e-6 only an absolute bound is meaningful
      } else {
        worst = std::max(worst, std::abs(out[i] - reference) / reference);
      }
    }
    EXPECT_LT(worst, variant == SchulerVariant::full ? 1e-4 : 2e-5) << int(variant);
  }
}

TEST(ShadingBatch, HardCases) {
  Samples s;
  const Vec3 n(0, 0, 1);
  for (double gloss : {0.0, 1.0}) {
    for (double ks : {0.0, 0.04, 1.0}) {
      s.add(make_geometry(n, n, n), ks, gloss);                                  // n·h = 1, e = 4096 at g = 1
      s.add(make_geometry(n, direction_from_cosine(0.8, 0), direction_from_cosine(0.8, 3.14159265358979)), ks, gloss);  // mirror, n·h = 1
      s.add(make_geometry(n, direction_from_cosine(1 - 1e-7, 0), direction_from_cosine(1, 0)), ks, gloss);  // n·h → 1
      s.add(make_geometry(n, direction_from_cosine(1e-6, 0), direction_from_cosine(1e-6, 3.1415)), ks, gloss);  // l·h → 0
      s.add(make_geometry(n, direction_from_cosine(1e-7, 0), direction_from_cosine(0.5, 1)), ks, gloss);     // n·l → 0+
      s.add(make_geometry(n, direction_from_cosine(-0.2, 0), direction_from_cosine(0.5, 1)), ks, gloss);     // light below
      s.add(make_geometry(n, direction_from_cosine(0.5, 0), direction_from_cosine(-0.1, 1)), ks, gloss);     // view below
    }
  }
  for (SchulerVariant variant : kVariants) {
    const std::vector<float> out = s.run(variant);
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double reference = s.reference(variant, i);
      ASSERT_TRUE(std::isfinite(out[i]) && out[i] >= 0) << int(variant) << " sample " << i;
      EXPECT_NEAR(out[i], reference, 2e-5 * reference + 1e-12) << int(variant) << " sample " << i;
    }
  }
}

TEST(ShadingBatch, BeyondTheFloatRangeGivesTheLargestFloat) {
  // l and v 1e-20 above the horizon on opposite sides: Optimized, (1 + e)/8 · n·l/(l·h)³, overflows float.
  Samples s;
  Geometry g;
  g.n_dot_l = g.n_dot_v = g.l_dot_h = 1e-20;
  g.n_dot_h = 1;
  s.add(g, 0.5, 1);
  EXPECT_GT(s.reference(SchulerVariant::optimized, 0), FLT_MAX);
  EXPECT_EQ(s.run(SchulerVariant::optimized)[0], FLT_MAX);
  // KSK grows only as n·l/(l·h)²: 5.1e22 here, still a float.
  EXPECT_NEAR(s.run(SchulerVariant::kelemen_szirmay_kalos)[0], s.reference(SchulerVariant::kelemen_szirmay_kalos, 0),
              1e-6 * s.reference(SchulerVariant::kelemen_szirmay_kalos, 0));
}

TEST(ShadingBatch, SpansOfDifferentSizesAreRefused) {
  const std::vector<float> a(4, 0.5f), b(3, 0.5f);
  std::vector<float> out(4);
  EXPECT_THROW(schuler_specular_batch(SchulerVariant::optimized, {a, a, a, b, a, a}, out), std::invalid_argument);
}

}  // namespace
}  // namespace matbake::shading
