// The OCIO wrapper, and what OCIO 2.1's sRGB curve differs from IEC 61966-2-1 by (pinned, so a
// change in either shows).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "matbake/color.hpp"
#include "matbake/ocio.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::color {
namespace {

constexpr const char* kLinear = "Linear Rec.709 (sRGB)";
constexpr const char* kSrgb = "sRGB - Texture";
constexpr const char* kGamma22 = "Gamma 2.2 Rec.709 - Texture";

// $OCIO set for the scope of one test.
class ScopedOcioVariable {
 public:
  explicit ScopedOcioVariable(const char* value) {
    if (const char* old = std::getenv("OCIO")) old_ = old;
    if (value) setenv("OCIO", value, 1);
    else unsetenv("OCIO");
  }
  ~ScopedOcioVariable() {
    if (old_.empty()) unsetenv("OCIO");
    else setenv("OCIO", old_.c_str(), 1);
  }

 private:
  std::string old_;
};

// Decodes all 256 8-bit codes, gray replicated to RGB, through an OCIO processor.
std::vector<float> decode_codes_with(const OcioProcessor& processor) {
  std::vector<float> rgb(256 * 3);
  for (int i = 0; i < 256 * 3; ++i) rgb[i] = float((i / 3) / 255.0);
  processor.apply(rgb, 3);
  return rgb;
}

OcioProcessor builtin_processor(const char* from, const char* to) {
  auto config = OcioConfig::load_builtin();
  EXPECT_TRUE(config);
  auto processor = config->processor(from, to);
  EXPECT_TRUE(processor);
  return processor.value();
}

TEST(Ocio, BuiltinConfigHasTheTextureSpaces) {
  ScopedOcioVariable unset(nullptr);
  auto config = OcioConfig::load();
  ASSERT_TRUE(config) << config.error().to_string();
  EXPECT_EQ(config->source(), "built-in");
  for (const char* name : {kLinear, kSrgb, kGamma22, "Raw", "srgb_tx"}) EXPECT_TRUE(config->has_colorspace(name)) << name;
  EXPECT_TRUE(config->is_scene_linear(kLinear));
  EXPECT_FALSE(config->is_scene_linear(kSrgb));
  EXPECT_EQ(config->colorspace_names().size(), 4u);
}

TEST(Ocio, SrgbCurveDiffersFromIecInTheToeOnly) {
  // OCIO 2.1 uses the C1-continuous break (0.03928, slope 12.9232) instead of IEC's 0.04045 / 12.92.
  const auto ocio = decode_codes_with(builtin_processor(kSrgb, kLinear));
  double worst = 0;
  int worst_code = 0;
  for (int code = 1; code < 256; ++code) {
    const double exact = linear_from_encoded(Transfer::srgb, code / 255.0);
    const double relative = std::abs(ocio[code * 3] - exact) / exact;
    if (relative > worst) worst = relative, worst_code = code;
    if (code > 10) {
      EXPECT_LT(relative, 1e-4) << code;  // above the toe: float rounding, fit noise
    }
  }
  EXPECT_GT(worst, 2.0e-4);
  EXPECT_LT(worst, 2.6e-4);
  EXPECT_LE(worst_code, 10);
}

TEST(Ocio, GammaSpaceMatchesTheBuiltinCurve) {
  const auto ocio = decode_codes_with(builtin_processor(kGamma22, kLinear));
  for (int code = 1; code < 256; ++code) {
    EXPECT_NEAR(ocio[code * 3], decode_table(Transfer::gamma22, 8)[code], 2e-6 * ocio[code * 3]) << code;
  }
}

TEST(Ocio, EightBitPathAgreesWithFloatPathAndKeepsAlpha) {
  const OcioProcessor processor = builtin_processor(kSrgb, kLinear);
  std::vector<uint8_t> codes(256 * 4);
  std::vector<float> values(codes.size());
  for (std::size_t i = 0; i < codes.size(); ++i) {
    codes[i] = uint8_t(i / 4);
    values[i] = float(codes[i] / 255.0);
  }
  std::vector<float> from_codes(codes.size());
  processor.apply(std::span<const uint8_t>(codes), from_codes, 4);
  processor.apply(values, 4);
  for (std::size_t i = 0; i < codes.size(); ++i) {
    EXPECT_NEAR(from_codes[i], values[i], 1e-6) << i;
    if (i % 4 == 3) {
      EXPECT_EQ(values[i], float(codes[i] / 255.0));  // alpha untouched
    }
  }
}

TEST(Ocio, EnvironmentVariableAndExplicitPathAreHonoured) {
  test::TempDir dir;
  const auto path = dir / "my.ocio";
  test::write_bytes(path, test::read_bytes(std::filesystem::path(MATBAKE_SOURCE_DIR) / "presets/ocio/config.ocio"));
  {
    ScopedOcioVariable set(path.c_str());
    auto config = OcioConfig::load();
    ASSERT_TRUE(config);
    EXPECT_EQ(config->source(), path.string());
  }
  auto explicit_config = OcioConfig::load(path);
  ASSERT_TRUE(explicit_config);
  EXPECT_EQ(explicit_config->source(), path.string());
}

TEST(Ocio, BadConfigsAndNamesAreErrors) {
  test::TempDir dir;
  auto missing = OcioConfig::load(dir / "none.ocio");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "OCIO config not found");

  test::write_bytes(dir / "bad.ocio", "ocio_profile_version: 2\ncolorspaces: [ {{{\n");
  auto bad = OcioConfig::load(dir / "bad.ocio");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().path, (dir / "bad.ocio").string());
  EXPECT_EQ(bad.error().message.rfind("cannot load OCIO config: ", 0), 0u) << bad.error().message;
  EXPECT_EQ(bad.error().message.find('\n'), std::string::npos);

  auto config = OcioConfig::load_builtin();
  ASSERT_TRUE(config);
  auto unknown = config->processor("ACEScg", kLinear);
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().message, "OCIO config has no colour space 'ACEScg'");
}

}  // namespace
}  // namespace matbake::color
