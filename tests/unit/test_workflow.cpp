// Workflow conversions: gloss ⇄ roughness mappings, the least-squares (base, metallic) solve and its
// explicit cases, the Khronos converter at its exact ends, ΔE and the lobe quadrature.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>

#include <cmath>
#include <numbers>
#include <random>

#include "matbake/workflow.hpp"

namespace matbake::workflow {
namespace {

double residual(const Vec3& kd, const Vec3& ks, const BaseMetallic& x) {
  const Vec3 d = diffuse_from_metal_rough(x.base, x.metallic) - kd;
  const Vec3 s = specular_from_metal_rough(x.base, x.metallic) - ks;
  return glm::dot(d, d) + glm::dot(s, s);
}

TEST(RoughnessMapping, WalterValuesOfTheIssue) {
  EXPECT_NEAR(roughness_from_gloss(0.0, RoughnessMapping::walter), 0.9036, 5e-5);  // sqrt(sqrt(2/3))
  EXPECT_NEAR(roughness_from_gloss(0.5, RoughnessMapping::walter), 0.4172, 5e-5);
  EXPECT_NEAR(roughness_from_gloss(1.0, RoughnessMapping::walter), 0.1486, 5e-5);
  EXPECT_EQ(roughness_from_gloss(-1, RoughnessMapping::walter), roughness_from_gloss(0, RoughnessMapping::walter));
}

TEST(RoughnessMapping, BothMappingsDecreaseAndInvert) {
  for (RoughnessMapping mapping : {RoughnessMapping::walter, RoughnessMapping::fitted}) {
    for (double f0 : {0.0, 0.04, 0.1, 0.33, 0.9, 1.0}) {
      double previous = 2;
      for (int i = 0; i <= 1000; ++i) {
        const double g = i / 1000.0;
        const double r = roughness_from_gloss(g, mapping, f0);
        EXPECT_LT(r, previous);
        previous = r;
        EXPECT_NEAR(gloss_from_roughness(r, mapping, f0), g, 1e-9) << roughness_mapping_name(mapping) << " g " << g;
      }
      EXPECT_EQ(gloss_from_roughness(1.0, mapping, f0), 0.0);  // rougher than any Schüler surface
      EXPECT_EQ(gloss_from_roughness(0.0, mapping, f0), 1.0);  // a mirror: the glossiest we have
    }
  }
  // Between rows the fitted mapping interpolates in F0.
  const double r0 = roughness_from_gloss(0.5, RoughnessMapping::fitted, 0.2);
  const double r1 = roughness_from_gloss(0.5, RoughnessMapping::fitted, 0.5);
  EXPECT_NEAR(roughness_from_gloss(0.5, RoughnessMapping::fitted, 0.35), (r0 + r1) / 2, 1e-12);
}

TEST(RoughnessMapping, FittedIsTheLeastSquaresOptimumAndBeatsWalter) {
  const LobeQuadrature q = make_lobe_quadrature(24);
  const LobeQuadrature fine = make_lobe_quadrature(48);
  for (double f0 : {0.04, 0.3, 0.9}) {
    for (int i = 0; i <= 32; i += 4) {
      const double g = i / 32.0;
      const double walter = lobe_error(q, f0, g, f0, roughness_from_gloss(g, RoughnessMapping::walter));
      const double fitted = lobe_error(q, f0, g, f0, roughness_from_gloss(g, RoughnessMapping::fitted, f0));
      const double khronos = lobe_error(q, f0, g, f0, 1 - g);
      EXPECT_LT(fitted, walter) << "F0 " << f0 << " g " << g;
      EXPECT_LT(fitted, khronos) << "F0 " << f0 << " g " << g;
    }
  }
  // The shipped table is what the fit gives (bench/fit_gloss_roughness regenerates it)…
  for (std::size_t row : {std::size_t(1), std::size_t(5)}) {
    for (int i : {0, 16, 32}) {
      EXPECT_NEAR(fitted_roughness_table(row)[i], best_roughness(fine, kFittedF0[row], i / 32.0), 1e-6) << i;
    }
  }
  // …and the quadrature has converged: half the resolution moves the optimum by < 0.005.
  EXPECT_NEAR(best_roughness(q, kDielectricF0, 0.5), fitted_roughness_table(1)[16], 0.005);
}

TEST(LobeQuadrature, WeightsCoverTheHemispherePerView) {
  const LobeQuadrature q = make_lobe_quadrature(64);
  double total = 0;
  for (const auto& p : q.pairs) total += p.weight;
  EXPECT_NEAR(total, 5 * 2 * std::numbers::pi, 0.01 * 5 * 2 * std::numbers::pi);
  EXPECT_EQ(lobe_error(q, 0.04, 0.5, 0.04, 0.3), lobe_error(q, Vec3(0.04), 0.5, Vec3(0.04), 0.3));
}

TEST(BaseMetallic, ExplicitCases) {
  const BaseMetallic black = base_metallic_from_spec_gloss(Vec3(0), Vec3(0));
  EXPECT_EQ(black.metallic, 1.0);
  EXPECT_EQ(black.base, Vec3(0));
  // Table 2.5.1 metals (Kd = 0): metallic 1, base = Ks.
  for (const Vec3& ks : {Vec3(1.0, 0.78, 0.34), Vec3(0.96, 0.64, 0.54), Vec3(0.97, 0.96, 0.91)}) {
    const BaseMetallic metal = base_metallic_from_spec_gloss(Vec3(0), ks);
    EXPECT_EQ(metal.metallic, 1.0);
    EXPECT_EQ(metal.base, ks);
  }
  const BaseMetallic plastic = base_metallic_from_spec_gloss({0.5, 0.2, 0.1}, Vec3(0.04));
  EXPECT_EQ(plastic.metallic, 0.0);
  EXPECT_EQ(plastic.base, Vec3(0.5, 0.2, 0.1));
  // 8-bit sRGB cannot hold 0.04: code 57 decodes to 0.0409, still read as the dielectric.
  EXPECT_EQ(base_metallic_from_spec_gloss({0.5, 0.2, 0.1}, Vec3(0.0409)).metallic, 0.0);
}

TEST(BaseMetallic, RecoversEveryMetalRoughColourExactly) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 base(u(rng), u(rng), u(rng));
    const double m = i % 5 == 0 ? 0.0 : i % 5 == 1 ? 1.0 : u(rng);
    const Vec3 kd = diffuse_from_metal_rough(base, m), ks = specular_from_metal_rough(base, m);
    const BaseMetallic solved = base_metallic_from_spec_gloss(kd, ks);
    EXPECT_LT(residual(kd, ks, solved), 1e-12) << i;
    // (base, m) is unique except where m = 0 hides the specular or m = 1 hides the diffuse.
    EXPECT_NEAR(solved.metallic, m, 1e-5) << i;
  }
}

TEST(BaseMetallic, LeastSquaresOnInconsistentColours) {
  // Coloured Ks with non-zero Kd, water's Ks = 0.02 and diamond's 0.17: no exact solution. The
  // solve is a local minimum and never worse than the Khronos converter.
  for (const auto& [kd, ks] : {std::pair{Vec3(0.3, 0.2, 0.1), Vec3(0.5, 0.4, 0.2)},
                               std::pair{Vec3(0.1, 0.2, 0.3), Vec3(0.02)}, std::pair{Vec3(0.05), Vec3(0.17)},
                               std::pair{Vec3(0.8), Vec3(0.9, 0.1, 0.1)}}) {
    const BaseMetallic x = base_metallic_from_spec_gloss(kd, ks);
    const double r = residual(kd, ks, x);
    EXPECT_LE(r, residual(kd, ks, khronos_base_metallic(kd, ks)) + 1e-15);
    for (double dm : {-0.01, 0.01}) {
      const double m = std::clamp(x.metallic + dm, 0.0, 1.0);
      EXPECT_LE(r, residual(kd, ks, {x.base, m}) + 1e-15);
    }
    for (int c = 0; c < 3; ++c) {
      for (double db : {-0.01, 0.01}) {
        BaseMetallic y = x;
        y.base[c] = std::clamp(y.base[c] + db, 0.0, 1.0);
        EXPECT_LE(r, residual(kd, ks, y) + 1e-15);
      }
    }
  }
}

TEST(Khronos, ExactAtPureDielectricAndPureMetal) {
  const BaseMetallic dielectric = khronos_base_metallic(Vec3(0.5), Vec3(0.04));
  EXPECT_NEAR(dielectric.metallic, 0.0, 1e-12);
  EXPECT_NEAR(dielectric.base.r, 0.5, 1e-12);
  const Vec3 gold(1.0, 0.78, 0.34);
  const BaseMetallic metal = khronos_base_metallic(Vec3(0), gold);
  EXPECT_NEAR(metal.metallic, 1.0, 1e-12);
  EXPECT_NEAR(metal.base.g, 0.78, 1e-12);
  EXPECT_NEAR(metal.base.b, 0.34, 1e-12);
  // Below the dielectric floor it gives up on the specular: metallic 0.
  EXPECT_EQ(khronos_base_metallic(Vec3(0.3), Vec3(0.02)).metallic, 0.0);
}

TEST(DeltaE, ClosedForms) {
  EXPECT_NEAR(delta_e_ab(Vec3(1), Vec3(0)), 100.0, 1e-3);  // L* 100 vs 0, both neutral
  // Middle grey: Y = 0.18 → L* = 116·0.18^(1/3) − 16.
  EXPECT_NEAR(delta_e_ab(Vec3(0.18), Vec3(0)), 116 * std::cbrt(0.18) - 16, 1e-3);
  EXPECT_EQ(delta_e_ab(Vec3(0.3, 0.2, 0.1), Vec3(0.3, 0.2, 0.1)), 0.0);
}

TEST(Workflow, MetalRoughToSpecGlossAndBack) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  for (RoughnessMapping mapping : {RoughnessMapping::walter, RoughnessMapping::fitted}) {
    for (int i = 0; i < 500; ++i) {
      // Within the range a Schüler gloss can say (the mapping's roughness at g = 1 and 0).
      const Vec3 base(u(rng), u(rng), u(rng));
      const double metallic = i % 2 ? 1.0 : u(rng);
      const double f0 = mean_f0(specular_from_metal_rough(base, metallic));
      // Within the range a Schüler gloss can say for this F0 (the roughness at g = 1 and 0).
      const double lo = roughness_from_gloss(1, mapping, f0), hi = roughness_from_gloss(0, mapping, f0);
      const MetalRough mr{base, metallic, lo + u(rng) * (hi - lo)};
      const SpecGloss sg = spec_gloss_from_metal_rough(mr, mapping);
      const MetalRough back = metal_rough_from_spec_gloss(sg, mapping);
      EXPECT_NEAR(back.roughness, mr.roughness, 1e-9);
      // What renders comes back within 1e-3 per channel; (base, metallic) itself exactly, except
      // where Ks is within that tolerance of 0.04 and is read as a pure dielectric.
      const SpecGloss again = spec_gloss_from_metal_rough(back, mapping);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(again.kd[c], sg.kd[c], 1e-3) << i;
        EXPECT_NEAR(again.ks[c], sg.ks[c], 1e-3) << i;
      }
      if (glm::length(sg.ks - Vec3(kDielectricF0)) > 2e-3) {
        EXPECT_NEAR(back.metallic, mr.metallic, 1e-5) << i;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.base[c], mr.base[c], 1e-4) << i;
      }
    }
  }
}

}  // namespace
}  // namespace matbake::workflow
