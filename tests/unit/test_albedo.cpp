// Directional albedo by numerical integration: closed forms, energy conservation for the models
// built to conserve it, and the known excesses of the others pinned.
#include <gtest/gtest.h>

#include <numbers>

#include "matbake/shading_catalog.hpp"

namespace matbake::shading {
namespace {

constexpr double kDegrees = std::numbers::pi / 180;

const ModelInfo& model(std::string_view name) {
  const ModelInfo* m = find_model(name);
  EXPECT_NE(m, nullptr) << name;
  return *m;
}

TEST(Albedo, LambertIsItsReflectanceAtEveryView) {
  for (double view : {0.0, 45.0, 85.0}) {
    const auto a = directional_albedo(model("lambert"), {0.7, 0, 0}, view * kDegrees, 64);
    EXPECT_NEAR(a.value, 0.7, 3 * a.error + 1e-3) << view;
  }
}

TEST(Albedo, SmoothMicrofacetSurfacesReflectTheirFresnelAtNormalIncidence) {
  // g = 1 is nearly a mirror: the albedo approaches F0 (Schlick's or the dielectric's).
  for (std::string_view name : {"cook-torrance", "ggx", "schuler-full"}) {
    for (double ks : {0.04, 0.5, 1.0}) {
      const auto a = directional_albedo(model(name), {0, ks, 1.0}, 0.0, 96);
      EXPECT_NEAR(a.value, ks, 0.01 * ks + 3 * a.error) << name << " ks " << ks;
    }
  }
}

TEST(Albedo, EnergyConservingModelsStayAtOrBelowOne) {
  for (const ModelInfo& m : models()) {
    if (!m.conserves_energy) continue;
    for (double view : {0.0, 60.0, 85.0}) {
      for (double gloss : {0.0, 0.5, 1.0}) {
        const auto a = directional_albedo(m, {1.0, 1.0, gloss}, view * kDegrees, 64);
        EXPECT_LE(a.value, 1.0 + 3 * a.error + 1e-3) << m.name << " view " << view << " g " << gloss;
        EXPECT_GE(a.value, 0.0);
      }
    }
  }
}

TEST(Albedo, KnownExcessesArePinned) {
  // Schüler's Optimized has 1/(l·h)³ and no G: at grazing view a smooth white specular reflects
  // an order of magnitude more than it receives (docs/shading.md has the table).
  const auto optimized = directional_albedo(model("schuler-optimized"), {0, 1.0, 1.0}, 89 * kDegrees, 64);
  EXPECT_GT(optimized.value, 10.0);
  // The slides' (m + 8)/(8π) is an approximation of the normalized lobe: slightly above 1 at
  // normal incidence for mid exponents.
  const auto normalized = directional_albedo(model("blinn-phong-normalized"), {0, 1.0, 0.5}, 0.0, 64);
  EXPECT_GT(normalized.value, 1.01);
  EXPECT_LT(normalized.value, 1.05);
}

}  // namespace
}  // namespace matbake::shading
