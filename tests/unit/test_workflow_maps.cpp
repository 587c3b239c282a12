// Whole-map conversions: the explicit cases of the issue, the error report, the dielectric F0
// extension values and the MR → Schüler → MR round trip.
#include <gtest/gtest.h>

#include <cmath>

#include "matbake/workflow_maps.hpp"

namespace matbake::workflow {
namespace {

material::Maps maps(const std::vector<pack::SourceInput>& inputs) {
  auto m = pack::load_sources(inputs, {});
  EXPECT_TRUE(m) << m.error().to_string();
  return *m;
}

Vec3 colour(const material::Maps& m, const char* name) {
  const auto& p = m.find(name)->pixels;
  return {p[0], p[1], p[2]};
}

TEST(WorkflowMaps, GoldIsAPureMetalWithNoColourError) {
  ConversionReport report;
  auto out = metal_rough_from_spec_gloss(maps({{"kd", {}, {0}}, {"ks", {}, {1.0, 0.78, 0.34}}, {"gloss", {}, {1}}}),
                                         RoughnessMapping::fitted, report);
  ASSERT_TRUE(out);
  EXPECT_EQ(out->find("metallic")->pixels[0], 1.0f);
  EXPECT_NEAR(colour(*out, "base_color").g, 0.78, 1e-7);
  EXPECT_NEAR(out->find("roughness")->pixels[0], roughness_from_gloss(1, RoughnessMapping::fitted, (1.0 + 0.78 + 0.34) / 3),
              1e-7);
  EXPECT_NEAR(report.errors.diffuse_delta_e.max, 0, 1e-12);
  EXPECT_NEAR(report.errors.specular.max, 0, 1e-7);
  EXPECT_EQ(report.errors.lobe.count, 1u);
  EXPECT_GT(report.errors.lobe.mean, 0.0);  // GGX is not Blinn-Phong
  EXPECT_EQ(report.texels, 1u);
  EXPECT_EQ(report.dielectric.texels, 0u);
}

TEST(WorkflowMaps, FittedMappingHasTheSmallerLobeErrorThanKhronos) {
  for (double g : {0.0, 0.5, 1.0}) {
    ConversionReport report;
    ASSERT_TRUE(metal_rough_from_spec_gloss(maps({{"kd", {}, {0.5, 0.3, 0.2}}, {"ks", {}, {0.04}}, {"gloss", {}, {g}}}),
                                            RoughnessMapping::fitted, report));
    EXPECT_LT(report.errors.lobe.mean, report.khronos_errors.lobe.mean) << g;
  }
}

TEST(WorkflowMaps, WaterAndDiamondGetExtensionValues) {
  for (const auto& [f0, ior] : {std::pair{0.02, 1.3294}, std::pair{0.17, 2.4032}}) {
    ConversionReport report;
    ASSERT_TRUE(metal_rough_from_spec_gloss(maps({{"kd", {}, {0.3}}, {"ks", {}, {f0}}, {"gloss", {}, {0.8}}}),
                                            RoughnessMapping::fitted, report));
    const DielectricF0& d = report.dielectric;
    EXPECT_EQ(d.texels, 1u);
    EXPECT_NEAR(d.mean_f0, f0, 1e-7);
    EXPECT_NEAR(d.ior, ior, 1e-4);
    EXPECT_NEAR(d.specular_color_factor, f0 / 0.04, 1e-5);
    EXPECT_NEAR(d.error_without_extensions.mean, std::abs(f0 - 0.04), 1e-7);
    EXPECT_NEAR(d.error_with_extensions.mean, 0.0, 1e-7);
  }
}

TEST(WorkflowMaps, HardCasesStayFinite) {
  for (double g : {0.0, 1.0}) {
    for (const Vec3& kd : {Vec3(0), Vec3(1), Vec3(0.5, 0.2, 0.1)}) {
      for (const Vec3& ks : {Vec3(0), Vec3(0.04), Vec3(1), Vec3(0.9, 0.6, 0.2)}) {
        ConversionReport report;
        auto out = metal_rough_from_spec_gloss(
            maps({{"kd", {}, {kd.r, kd.g, kd.b}}, {"ks", {}, {ks.r, ks.g, ks.b}}, {"gloss", {}, {g}}}),
            RoughnessMapping::fitted, report);
        ASSERT_TRUE(out);
        for (const auto& [name, map] : out->maps) {
          for (float v : map.pixels) EXPECT_TRUE(v >= 0 && v <= 1) << name;
        }
        for (double e : {report.errors.diffuse_delta_e.max, report.errors.specular.max, report.errors.lobe.max}) {
          EXPECT_TRUE(std::isfinite(e));
        }
      }
    }
  }
}

TEST(WorkflowMaps, MetalRoughHardCases) {
  // Base colour 0 and 1, metallic 0 and 1, roughness at and beyond the ends of what gloss can say.
  for (double base : {0.0, 1.0}) {
    for (double metallic : {0.0, 1.0}) {
      for (double roughness : {0.0, 0.04, 1.0}) {
        ConversionReport report;
        auto sg = spec_gloss_from_metal_rough(
            maps({{"base_color", {}, {base}}, {"metallic", {}, {metallic}}, {"roughness", {}, {roughness}}}),
            RoughnessMapping::fitted, report);
        ASSERT_TRUE(sg);
        EXPECT_NEAR(colour(*sg, "kd").r, base * (1 - metallic), 1e-7);
        EXPECT_NEAR(colour(*sg, "ks").r, 0.04 + metallic * (base - 0.04), 1e-7);
        const float g = sg->find("gloss")->pixels[0];
        EXPECT_EQ(g, roughness == 1.0 ? 0.0f : 1.0f);  // beyond the ends: clamped
        EXPECT_TRUE(std::isfinite(report.errors.lobe.max));
      }
    }
  }
}

TEST(WorkflowMaps, MetalRoughToSchulerAndBack) {
  const std::vector<pack::SourceInput> mr = {{"base_color", {}, {0.8, 0.5, 0.2}}, {"metallic", {}, {0.6}},
                                             {"roughness", {}, {0.4}}, {"occlusion", {}, {0.7}}};
  ConversionReport there, back;
  auto sg = spec_gloss_from_metal_rough(maps(mr), RoughnessMapping::fitted, there);
  ASSERT_TRUE(sg);
  EXPECT_NEAR(colour(*sg, "kd").r, 0.8 * 0.4, 1e-7);
  EXPECT_NEAR(colour(*sg, "ks").b, 0.04 + 0.6 * (0.2 - 0.04), 1e-7);
  EXPECT_EQ(sg->find("occlusion")->pixels[0], 0.7f);  // passed through
  EXPECT_LT(there.errors.diffuse_delta_e.max, 1e-4);
  auto mr_again = metal_rough_from_spec_gloss(*sg, RoughnessMapping::fitted, back);
  ASSERT_TRUE(mr_again);
  EXPECT_NEAR(mr_again->find("metallic")->pixels[0], 0.6, 1e-5);
  EXPECT_NEAR(mr_again->find("roughness")->pixels[0], 0.4, 1e-6);
  EXPECT_NEAR(colour(*mr_again, "base_color").g, 0.5, 1e-5);
}

TEST(WorkflowMaps, MissingSourcesAreUsageErrors) {
  ConversionReport report;
  auto out = metal_rough_from_spec_gloss(maps({{"kd", {}, {0.5}}, {"ks", {}, {0.04}}}), RoughnessMapping::fitted, report);
  ASSERT_FALSE(out);
  EXPECT_TRUE(out.error().usage);
  EXPECT_EQ(out.error().message, "the conversion needs gloss");
}

}  // namespace
}  // namespace matbake::workflow
