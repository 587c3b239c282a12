// Image I/O: decode at read, encode at write, alpha unassociated on both sides, every layout and
// odd size, non-finite input rejected, atomic writes.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <limits>

#include "matbake/image.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::image {
namespace {

using color::Transfer;
using test::list_folder;
using test::read_raw;
using test::TempDir;
using test::write_raw;

TEST(ImageIo, AlphaIsUnassociatedAndNeverTransferred) {
  // DEBIAN-NOTES: OIIO's default would premultiply (255,128,64,128) on read and divide on write.
  TempDir dir;
  write_raw(dir / "in.png", 1, 1, 4, "uint8", {255, 128, 64, 128});
  auto image = read_image(dir / "in.png", Transfer::srgb);
  ASSERT_TRUE(image) << image.error().to_string();
  EXPECT_EQ(image->alpha_channel, 3);
  EXPECT_EQ(image->pixels[0], 1.0f);
  EXPECT_EQ(image->pixels[1], color::decode_table(Transfer::srgb, 8)[128]);
  EXPECT_EQ(image->pixels[2], color::decode_table(Transfer::srgb, 8)[64]);
  EXPECT_EQ(image->pixels[3], float(128.0 / 255.0));

  ASSERT_TRUE(write_image(*image, dir / "linear.exr", {Transfer::linear, SampleType::f32, "", "Linear"}));
  const auto exr = read_raw(dir / "linear.exr");
  EXPECT_EQ(exr.samples, (std::vector<double>{1.0, image->pixels[1], image->pixels[2], image->pixels[3]}));

  auto linear = read_image(dir / "linear.exr", Transfer::linear);
  ASSERT_TRUE(linear);
  ASSERT_TRUE(write_image(*linear, dir / "back.png", {Transfer::srgb, SampleType::u8, "", "sRGB"}));
  EXPECT_EQ(read_raw(dir / "back.png").samples, (std::vector<double>{255, 128, 64, 128}));
}

TEST(ImageIo, EveryLayoutAndOddSizeRoundTripsThroughLinearHalf) {
  TempDir dir;
  const std::vector<std::vector<std::string>> names = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  for (int channels = 1; channels <= 4; ++channels) {
    for (auto [w, h] : {std::pair{1, 1}, std::pair{7, 5}, std::pair{3, 1}}) {
      std::vector<double> codes(std::size_t(w) * h * channels);
      for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = double((i * 37 + 11) % 256);
      const auto in = dir / ("in" + std::to_string(channels) + ".png");
      write_raw(in, w, h, channels, "uint8", codes, names[channels - 1]);
      auto image = read_image(in, Transfer::srgb);
      ASSERT_TRUE(image);
      EXPECT_EQ(image->width, w);
      EXPECT_EQ(image->height, h);
      EXPECT_EQ(image->channel_names, names[channels - 1]);
      // Half keeps 11 significant bits: enough for every 8-bit sRGB code to come back.
      ASSERT_TRUE(write_image(*image, dir / "mid.exr", {Transfer::linear, SampleType::half, "", ""}));
      EXPECT_EQ(read_raw(dir / "mid.exr").channel_names, names[channels - 1]);
      auto mid = read_image(dir / "mid.exr", Transfer::linear);
      ASSERT_TRUE(mid);
      ASSERT_TRUE(write_image(*mid, dir / "out.png", {Transfer::srgb, SampleType::u8, "", ""}));
      const auto out = read_raw(dir / "out.png");
      EXPECT_EQ(out.samples, codes) << channels << " channels, " << w << "x" << h;
    }
  }
}

TEST(ImageIo, SixteenBitCodesRoundTripThroughFloat) {
  TempDir dir;
  std::vector<double> codes;
  for (int i = 0; i < 65536; i += 13) codes.push_back(i);
  codes.resize(codes.size() / 3 * 3);
  const int w = int(codes.size() / 3);
  write_raw(dir / "in.png", w, 1, 3, "uint16", codes);
  auto image = read_image(dir / "in.png", Transfer::srgb);
  ASSERT_TRUE(image);
  ASSERT_TRUE(write_image(*image, dir / "mid.tif", {Transfer::linear, SampleType::f32, "", ""}));
  auto mid = read_image(dir / "mid.tif", Transfer::linear);
  ASSERT_TRUE(mid);
  ASSERT_TRUE(write_image(*mid, dir / "out.png", {Transfer::srgb, SampleType::u16, "", ""}));
  EXPECT_EQ(read_raw(dir / "out.png").samples, codes);
}

// Samples not stored as we keep them are converted by us, band by band: a channel type each
// (half colour, float alpha) over more than one band, and 32-bit integers.
TEST(ImageIo, PerChannelAndWideTypesAreConvertedExactly) {
  TempDir dir;
  const int w = 300, h = 1000;  // 1.2 M samples: two bands of rows
  OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::FLOAT);
  spec.channelformats = {OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF, OIIO::TypeDesc::HALF, OIIO::TypeDesc::FLOAT};
  spec.alpha_channel = 3;
  std::vector<float> values(std::size_t(w) * h * 4);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = float(i % 4093) / 4093.0f;
  const auto mixed = dir / "mixed.exr";
  {
    auto out = OIIO::ImageOutput::create(mixed.string());
    ASSERT_TRUE(out && out->open(mixed.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data()) && out->close());
  }
  auto image = read_image(mixed, Transfer::linear);
  ASSERT_TRUE(image) << image.error().to_string();
  ASSERT_EQ(image->pixels.size(), values.size());
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const float stored = i % 4 == 3 ? values[i] : float(Imath::half(values[i]));
    wrong += image->pixels[i] != stored;
  }
  EXPECT_EQ(wrong, 0u);

  {
    const auto integers = dir / "uint32.tif";
    OIIO::ImageSpec spec32(3, 1, 1, OIIO::TypeDesc::UINT32);
    const std::uint32_t codes[3] = {0, 1u << 30, 0xffffffffu};
    auto out = OIIO::ImageOutput::create(integers.string());
    ASSERT_TRUE(out && out->open(integers.string(), spec32));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT32, codes) && out->close());
    auto read = read_image(integers, Transfer::linear);
    ASSERT_TRUE(read) << read.error().to_string();
    EXPECT_EQ(read->pixels[0], 0.0f);
    EXPECT_NEAR(read->pixels[1], 0.25, 1e-7);
    EXPECT_EQ(read->pixels[2], 1.0f);
  }
}

TEST(ImageIo, NonFiniteSamplesAreRejectedAndCounted) {
  TempDir dir;
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  for (const char* format : {"float", "half"}) {
    const auto path = dir / (std::string(format) + ".exr");
    write_raw(path, 3, 1, 3, format, {0.5, nan, inf, -inf, 0.25, nan, nan, 1.0, 0.0});
    auto image = read_image(path, Transfer::srgb);
    ASSERT_FALSE(image);
    EXPECT_EQ(image.error().path, path.string());
    EXPECT_EQ(image.error().message, "contains 3 NaN and 2 Inf samples (the first at x 0, y 0, channel 1); matbake rejects non-finite texels");
  }
}

TEST(ImageIo, DecodeOverflowIsRejectedButHdrAndNegativesPass) {
  TempDir dir;
  write_raw(dir / "huge.exr", 2, 1, 1, "float", {1e30, 2.0});
  auto huge = read_image(dir / "huge.exr", Transfer::srgb);
  ASSERT_FALSE(huge);
  EXPECT_EQ(huge.error().message, "1 samples overflow float when decoded from srgb (inputs above about 1e16)");
  EXPECT_TRUE(read_image(dir / "huge.exr", Transfer::linear));  // nothing to decode: fine

  write_raw(dir / "hdr.exr", 2, 1, 1, "float", {4.0, -0.5});
  auto hdr = read_image(dir / "hdr.exr", Transfer::srgb);
  ASSERT_TRUE(hdr);
  EXPECT_FLOAT_EQ(hdr->pixels[0], float(std::pow(4.055 / 1.055, 2.4)));
  EXPECT_FLOAT_EQ(hdr->pixels[1], -float(std::pow(0.555 / 1.055, 2.4)));
}

TEST(ImageIo, UnsupportedChannelCountIsAnError) {
  TempDir dir;
  write_raw(dir / "five.exr", 2, 2, 5, "half", std::vector<double>(20, 0.5));
  auto image = read_image(dir / "five.exr", Transfer::linear);
  ASSERT_FALSE(image);
  EXPECT_EQ(image.error().message, "5 channels; matbake reads 1 to 4 (gray, gray+alpha, RGB, RGBA)");
}

TEST(ImageIo, MissingAndNonImageFilesAreErrors) {
  TempDir dir;
  auto missing = read_image(dir / "nope.png", Transfer::srgb);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().message, "no such file");
  test::write_bytes(dir / "text.png", "this is not a PNG\n");
  auto text = read_image(dir / "text.png", Transfer::srgb);
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().message.rfind("not a readable image", 0), 0u) << text.error().message;
  EXPECT_EQ(text.error().message.find('\n'), std::string::npos);
}

// An OpenEXR attribute: name, type, the size it declares and the bytes that follow.
std::string exr_attribute(const std::string& name, const std::string& type, std::uint32_t declared,
                          const std::string& value) {
  std::string bytes = name + '\0' + type + '\0';
  for (int shift = 0; shift < 32; shift += 8) bytes += char((declared >> shift) & 0xff);
  return bytes + value;
}

std::string exr_start(std::uint32_t version) {
  std::string bytes = "\x76\x2f\x31\x01";
  for (int shift = 0; shift < 32; shift += 8) bytes += char((version >> shift) & 0xff);
  return bytes;
}

// OpenEXR's C++ header reader allocates what an attribute declares before reading it: a 40-byte
// file declaring 2 GB cost 2.2 GB and 7.5 s before "Unexpected end of file". OpenEXR's C core
// checks the header first (exr_header.cpp), by content whatever the name, from a file or memory.
TEST(ImageIo, ExrHeaderDeclaringMoreThanTheFileHoldsIsRefused) {
  TempDir dir;
  const std::string single = exr_start(2) + exr_attribute("owner", "string", 0x7fffff00u, "abc");
  const std::string expected = "not a readable image: OpenEXR header: Attribute 'owner', type 'string': Invalid size 2147483392";
  test::write_bytes(dir / "big.exr", single);
  auto image = read_image(dir / "big.exr", Transfer::linear);
  ASSERT_FALSE(image);
  EXPECT_EQ(image.error().message, expected);
  const std::span bytes(reinterpret_cast<const unsigned char*>(single.data()), single.size());
  auto decoded = decode_image(bytes, "big.png", Transfer::linear);
  ASSERT_FALSE(decoded);
  EXPECT_EQ(decoded.error().message, expected);

  test::write_bytes(dir / "negative.exr", exr_start(2) + exr_attribute("comments", "string", 0x80000000u, ""));
  auto refused = read_image(dir / "negative.exr", Transfer::linear);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message,
            "not a readable image: OpenEXR header: Attribute 'comments', type 'string': Invalid negative size -2147483648");

  // Found by fuzzing: a 1.3 GB opaque attribute in a 0.7 KB file, which the C++ reader allocated
  // and cleared (and OIIO's reader on the C core divided by zero when that allocation failed).
  const auto opaque = std::filesystem::path(MATBAKE_SOURCE_DIR) / "tests/fuzz/regressions/image/exr-opaque-attribute-declares-1.3GB.exr";
  auto fuzzed = read_image(opaque, Transfer::linear);
  ASSERT_FALSE(fuzzed);
  EXPECT_EQ(fuzzed.error().message.rfind("not a readable image: OpenEXR header: Attribute 'chnanels'", 0), 0u)
      << fuzzed.error().message;
  EXPECT_NE(fuzzed.error().message.find("Invalid size 1351155785"), std::string::npos) << fuzzed.error().message;
  // And one without a data window, on which OIIO's reader over the core divided by zero.
  auto no_window = read_image(opaque.parent_path() / "exr-core-reader-divides-by-zero.exr", Transfer::linear);
  ASSERT_FALSE(no_window);
  EXPECT_EQ(no_window.error().message, "not a readable image: OpenEXR header: 'dataWindow' attribute not found");

  // A real multi-part file (two subimages, written by OIIO) is read: its first part.
  // (Parts share their display window, as OpenEXR requires.)
  OIIO::ImageSpec specs[2] = {OIIO::ImageSpec(3, 2, 3, OIIO::TypeDesc::HALF), OIIO::ImageSpec(1, 1, 1, OIIO::TypeDesc::FLOAT)};
  specs[1].full_width = 3;
  specs[1].full_height = 2;
  const std::vector<float> first = {0.0f, 0.25f, 0.5f, 1.0f, 2.0f, 4.0f, 0.125f, 0.75f, 8.0f,
                                    16.0f, 0.0625f, 0.375f, 0.5f, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f};
  const float other = 3.0f;
  const auto real = dir / "real-parts.exr";
  auto out = OIIO::ImageOutput::create(real.string());
  ASSERT_TRUE(out && out->supports("multiimage"));
  ASSERT_TRUE(out->open(real.string(), 2, specs)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, first.data()));
  ASSERT_TRUE(out->open(real.string(), specs[1], OIIO::ImageOutput::AppendSubimage));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, &other) && out->close());
  ASSERT_NE(test::read_bytes(real).find("name"), std::string::npos);  // it is multi-part: parts are named
  auto read = read_image(real, Transfer::linear);
  ASSERT_TRUE(read) << read.error().to_string();
  EXPECT_EQ(read->pixels, first);
}

// check_image_bytes gives the layout decode_image gives (its refusals: PngDecode's damaged files).
TEST(ImageIo, CheckingBytesGivesTheDecodedLayout) {
  Image noise;
  noise.width = 300, noise.height = 200, noise.channels = 4, noise.alpha_channel = 3;
  noise.channel_names = {"R", "G", "B", "A"};
  for (std::size_t i = 0; i < noise.sample_count(); ++i) noise.pixels.push_back(float((i * 2654435761u) % 251) / 250.0f);
  auto png = encode_image(noise, "noise.png", {.type = SampleType::u8});
  ASSERT_TRUE(png) << png.error().to_string();
  const std::span bytes(reinterpret_cast<const unsigned char*>(png->data()), png->size());
  auto checked = check_image_bytes(bytes, "noise.png");
  auto decoded = decode_image(bytes, "noise.png", Transfer::linear);
  ASSERT_TRUE(checked && decoded);
  EXPECT_EQ(checked->width, 300);
  EXPECT_EQ(checked->height, 200);
  EXPECT_EQ(checked->channels, 4);
  EXPECT_EQ(checked->alpha_channel, decoded->alpha_channel);
  EXPECT_EQ(checked->channel_names, decoded->channel_names);
}

// Inputs found by tests/fuzz/fuzz_image that made OIIO 2.4 read out of bounds (oiio_icc_override.cpp,
// oiio/checked_mem_reader.cpp; the PNG is read by libspng now, which ignores the profile):
// a PNG whose ICC profile's text tags point past it (SIGSEGV in release) and an EXR decoded from
// memory whose line offsets point before the buffer (an ASan report with OpenEXR's C++ reader;
// the C core refuses its header). Both are plain errors.
TEST(ImageIo, OutOfBoundsOffsetsInsideFilesAreErrorsNotCrashes) {
  const std::filesystem::path regressions = std::filesystem::path(MATBAKE_SOURCE_DIR) / "tests/fuzz/regressions/image";
  const auto png = regressions / "png-damaged-icc-profile.png";
  auto from_file = read_image(png, Transfer::srgb);
  ASSERT_FALSE(from_file);
  EXPECT_EQ(from_file.error().path, png.string());
  const auto exr = regressions / "exr-line-offset-outside-file.exr";
  const std::string bytes = test::read_bytes(exr);
  ASSERT_FALSE(bytes.empty());
  auto from_memory = decode_image(std::span(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()),
                                  "texture.exr", Transfer::linear);
  ASSERT_FALSE(from_memory);
  EXPECT_EQ(from_memory.error().path, "texture.exr");
}

// The guard is the ICC decoder in effect: OIIO's own would add ICCProfile:copyright and
// ICCProfile:dscm from this file's profile (as oiiotool shows); the profile's bytes stay.
TEST(ImageIo, OiioIccDecoderIsReplacedByTheGuard) {
  const auto png = std::filesystem::path(MATBAKE_TESTDATA_DIR) / "gltf/BoxTextured/glTF-pbrSpecularGlossiness/CesiumLogoFlat.png";
  if (!std::filesystem::is_regular_file(png)) {
    GTEST_SKIP() << png.string() << " is absent (it comes with the project's shared folder, not with a clone)";
  }
  auto in = OIIO::ImageInput::open(png.string());
  ASSERT_TRUE(in) << OIIO::geterror();
  ASSERT_NE(in->spec().find_attribute("ICCProfile"), nullptr);
  EXPECT_EQ(in->spec().find_attribute("ICCProfile")->type().size(), 2008u);
  EXPECT_EQ(in->spec().find_attribute("ICCProfile:copyright"), nullptr);
  EXPECT_EQ(in->spec().find_attribute("ICCProfile:dscm"), nullptr);
}

// The same in the CLI, which does not link OIIO: its module is loaded RTLD_LOCAL on first need, and
// libmatbake's replacement must still be the one OIIO's readers call. The damaged profile of the
// PNG above, moved into a TIFF (whose reader decodes profiles too; PNG is read by libspng now):
// oiiotool aborts on it, and with the replacement disabled the CLI did too (SIGSEGV in OIIO's
// decode_icc_profile, under ASan).
TEST(ImageIo, CliWithOiioLoadedOnDemandStillUsesTheIccGuard) {
  TempDir dir;
  const auto tif = std::filesystem::path(MATBAKE_SOURCE_DIR) / "tests/fuzz/regressions/image/tiff-damaged-icc-profile.tif";
  const auto r = test::matbake({"convert", tif.string(), "-o", (dir / "out.exr").string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;  // the profile is kept as bytes; the pixels are fine
  auto out = read_image(dir / "out.exr", Transfer::linear);
  ASSERT_TRUE(out) << out.error().to_string();
  EXPECT_EQ(out->sample_count(), 12u);
}

TEST(ImageIo, FailedWriteLeavesTheExistingOutputAndNoTemporaryFile) {
  TempDir dir;
  write_raw(dir / "in.png", 2, 2, 3, "uint8", std::vector<double>(12, 200));
  test::write_bytes(dir / "out.xyz", "previous good output");
  auto image = read_image(dir / "in.png", Transfer::srgb);
  ASSERT_TRUE(image);
  // No writer for the extension: fails after the temporary file was reserved.
  Status s = write_image(*image, dir / "out.xyz", {Transfer::linear, SampleType::half, "", ""});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().path, (dir / "out.xyz").string());
  EXPECT_EQ(s.error().message.rfind("no image writer for this extension", 0), 0u) << s.error().message;
  EXPECT_EQ(test::read_bytes(dir / "out.xyz"), "previous good output");
  EXPECT_EQ(list_folder(dir.path()), (std::vector<std::string>{"in.png", "out.xyz"}));

  // A folder that does not exist is made; one that cannot be (under a file) is a clean error.
  EXPECT_TRUE(write_image(*image, dir / "new" / "sub" / "out.exr", {}));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "new" / "sub" / "out.exr"));
  Status under_file = write_image(*image, dir / "in.png" / "out.exr", {});
  ASSERT_FALSE(under_file);
  EXPECT_EQ(under_file.error().message.rfind("cannot make the output folder: ", 0), 0u) << under_file.error().message;
}

TEST(ImageIo, WritesAreDeterministic) {
  TempDir dir;
  write_raw(dir / "in.png", 5, 3, 4, "uint8", std::vector<double>(60, 77));
  auto image = read_image(dir / "in.png", Transfer::srgb);
  ASSERT_TRUE(image);
  for (const char* ext : {".exr", ".png", ".tif"}) {
    const SampleType type = std::string(ext) == ".png" ? SampleType::u16 : SampleType::half;
    ASSERT_TRUE(write_image(*image, dir / (std::string("a") + ext), {Transfer::linear, type, "", "Linear"}));
    ASSERT_TRUE(write_image(*image, dir / (std::string("b") + ext), {Transfer::linear, type, "", "Linear"}));
    EXPECT_EQ(test::read_bytes(dir / (std::string("a") + ext)), test::read_bytes(dir / (std::string("b") + ext))) << ext;
  }
}

}  // namespace
}  // namespace matbake::image
