// The convert module: planning (built-in vs OCIO), defaults, and the conversion of one file.
#include <gtest/gtest.h>

#include <cmath>

#include "matbake/convert.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::convert {
namespace {

using image::SampleType;
using test::read_raw;
using test::TempDir;
using test::write_raw;

Options options(std::string from, std::string to) {
  Options o;
  o.from = std::move(from);
  o.to = std::move(to);
  return o;
}

TEST(PlanConversion, BuiltinTransfersNeedNoOcio) {
  auto plan = plan_conversion(options("srgb", "linear"));
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->decode, color::Transfer::srgb);
  EXPECT_EQ(plan->encode, color::Transfer::linear);
  EXPECT_FALSE(plan->ocio.has_value());
  EXPECT_TRUE(plan->target_is_linear);
  EXPECT_FALSE(plan_conversion(options("linear", "gamma2.2"))->target_is_linear);
}

TEST(PlanConversion, OcioNamesAndMixingThem) {
  auto plan = plan_conversion(options("sRGB - Texture", "Linear Rec.709 (sRGB)"));
  ASSERT_TRUE(plan) << plan.error().to_string();
  EXPECT_TRUE(plan->ocio.has_value());
  EXPECT_TRUE(plan->target_is_linear);
  EXPECT_EQ(plan->decode, color::Transfer::linear);  // OCIO sees the stored values

  auto mixed = plan_conversion(options("srgb", "Linear Rec.709 (sRGB)"));
  ASSERT_FALSE(mixed);
  EXPECT_TRUE(mixed.error().usage);
  auto unknown = plan_conversion(options("srgbb", "linear"));
  ASSERT_FALSE(unknown);
  EXPECT_TRUE(unknown.error().usage);
}

TEST(ConvertDefaults, SampleTypesAndOutputNames) {
  EXPECT_EQ(default_sample_type("a.exr", true, SampleType::u8), SampleType::half);
  EXPECT_EQ(default_sample_type("a.png", true, SampleType::u8), SampleType::u16);
  EXPECT_EQ(default_sample_type("a.png", false, SampleType::u8), SampleType::u8);
  EXPECT_EQ(default_sample_type("a.tif", false, SampleType::f32), SampleType::u16);
  EXPECT_EQ(output_path_in_folder("x/wood.png", "out", "", true), std::filesystem::path("out/wood.exr"));
  EXPECT_EQ(output_path_in_folder("wood.exr", "out", "", false), std::filesystem::path("out/wood.png"));
  EXPECT_EQ(output_path_in_folder("wood.png", "out", "tif", true), std::filesystem::path("out/wood.tif"));
  EXPECT_TRUE(is_supported_output_extension("a.TIFF"));
  EXPECT_FALSE(is_supported_output_extension("a.jpg"));
}

TEST(ConvertFile, SrgbPngToLinearExrHoldsTheExactTable) {
  TempDir dir;
  std::vector<double> codes(256);
  for (int i = 0; i < 256; ++i) codes[i] = i;
  write_raw(dir / "ramp.png", 16, 16, 1, "uint8", codes);
  const auto o = options("srgb", "linear");
  auto plan = plan_conversion(o);
  Options as_float = o;
  as_float.bits = SampleType::f32;
  auto report = convert_file(*plan, dir / "ramp.png", dir / "ramp.exr", as_float);
  ASSERT_TRUE(report) << report.error().to_string();
  EXPECT_EQ(report->input_type, SampleType::u8);
  EXPECT_EQ(report->output_type, SampleType::f32);
  const auto out = read_raw(dir / "ramp.exr");
  for (int i = 0; i < 256; ++i) ASSERT_EQ(out.samples[i], double(color::decode_table(color::Transfer::srgb, 8)[i]));
}

TEST(ConvertFile, OcioPathAgreesWithTheExactPathWithinItsMeasuredDifference) {
  TempDir dir;
  std::vector<double> rgb;
  for (int i = 0; i < 256; ++i) rgb.insert(rgb.end(), {double(i), double(255 - i), double(i / 2)});
  write_raw(dir / "in.png", 256, 1, 3, "uint8", rgb);
  Options o = options("sRGB - Texture", "Linear Rec.709 (sRGB)");
  o.bits = SampleType::f32;
  auto report = convert_file(*plan_conversion(o), dir / "in.png", dir / "ocio.exr", o);
  ASSERT_TRUE(report) << report.error().to_string();
  const auto out = read_raw(dir / "ocio.exr");
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    const double exact = color::linear_from_encoded(color::Transfer::srgb, rgb[i] / 255.0);
    EXPECT_NEAR(out.samples[i], exact, 2.6e-4 * exact + 1e-7) << i;
  }
}

TEST(ConvertFile, RefusalsLeaveNothingBehind) {
  TempDir dir;
  write_raw(dir / "gray.png", 2, 2, 1, "uint8", {1, 2, 3, 4});
  const auto builtin = options("srgb", "linear");
  auto plan = plan_conversion(builtin);

  auto same = convert_file(*plan, dir / "gray.png", dir / "gray.png", builtin);
  ASSERT_FALSE(same);
  EXPECT_EQ(same.error().message, "is an input; matbake never overwrites its inputs");

  Options eight_bit_exr = builtin;
  eight_bit_exr.bits = SampleType::u8;
  auto wrong_type = convert_file(*plan, dir / "gray.png", dir / "out.exr", eight_bit_exr);
  ASSERT_FALSE(wrong_type);
  EXPECT_TRUE(wrong_type.error().usage);

  auto jpeg_out = convert_file(*plan, dir / "gray.png", dir / "out.jpg", builtin);
  ASSERT_FALSE(jpeg_out);
  EXPECT_TRUE(jpeg_out.error().usage);

  const auto ocio = options("sRGB - Texture", "Linear Rec.709 (sRGB)");
  auto gray_ocio = convert_file(*plan_conversion(ocio), dir / "gray.png", dir / "out.exr", ocio);
  ASSERT_FALSE(gray_ocio);
  EXPECT_EQ(gray_ocio.error().message, "OCIO colour spaces need RGB or RGBA; this image has 1 channel(s)");

  EXPECT_EQ(test::list_folder(dir.path()), std::vector<std::string>{"gray.png"});
}

}  // namespace
}  // namespace matbake::convert
