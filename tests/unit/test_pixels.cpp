// Interleaved kernels: per-channel transfers (alpha never transferred), every channel count, and a
// buffer large enough to be split across threads.
#include <gtest/gtest.h>

#include <Imath/half.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "matbake/pixels.hpp"

namespace matbake::color {
namespace {

const std::vector<Transfer> kRgba = {Transfer::srgb, Transfer::srgb, Transfer::srgb, Transfer::linear};

TEST(Pixels, EightBitDecodeUsesOneTablePerChannel) {
  const std::vector<uint8_t> in = {255, 128, 64, 128, 0, 1, 2, 3};
  std::vector<float> out(in.size());
  decode_pixels(std::span<const uint8_t>(in), out, kRgba);
  EXPECT_EQ(out[0], 1.0f);
  EXPECT_EQ(out[1], decode_table(Transfer::srgb, 8)[128]);
  EXPECT_EQ(out[2], decode_table(Transfer::srgb, 8)[64]);
  EXPECT_EQ(out[3], float(128.0 / 255.0));  // alpha: linear
  EXPECT_EQ(out[7], float(3.0 / 255.0));
}

// The branch-free 8-bit kernel (per channel count) against rounding the float64 formula: every
// 509th float in [0, 1] (2.1M, all binades), the floats around every code boundary, and values
// outside [0, 1], NaN and Inf. bench/float_sweep checks every float in [0, 1].
TEST(Pixels, EightBitEncodeEqualsRoundingTheFloat64FormulaForEveryChannelCount) {
  std::vector<float> in;
  for (uint32_t b = 0; b <= std::bit_cast<uint32_t>(1.0f); b += 509) in.push_back(std::bit_cast<float>(b));
  for (Transfer t : {Transfer::linear, Transfer::srgb, Transfer::gamma22}) {
    for (int k = 1; k <= 255; ++k) {
      float x = float(linear_from_encoded(t, (k - 0.5) / 255));
      for (int step = 0; step < 3; ++step) x = std::nextafter(x, 0.0f);
      for (int step = 0; step < 6; ++step, x = std::nextafter(x, 2.0f)) in.push_back(x);
    }
  }
  for (float v : {-1e30f, -1.0f, -0.0f, 1.0f, 1.0000001f, 3.0f, 1e30f, std::numeric_limits<float>::infinity(),
                  -std::numeric_limits<float>::infinity(), std::nanf("")}) {
    in.push_back(v);
  }
  for (std::size_t channels = 1; channels <= 4; ++channels) {
    const std::vector<Transfer> transfers = {Transfer::srgb, Transfer::gamma22, Transfer::linear, Transfer::srgb};
    const std::span<const Transfer> used(transfers.data(), channels);
    const std::vector<float> samples(in.begin(), in.begin() + std::ptrdiff_t(in.size() / channels * channels));
    std::vector<uint8_t> codes(samples.size());
    encode_pixels(samples, codes, used);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      ASSERT_EQ(codes[i], quantize_reference(used[i % channels], 8, samples[i]))
          << channels << " channels, x = " << samples[i] << ", " << transfer_name(used[i % channels]);
    }
  }
}

TEST(Pixels, EveryChannelCountRoundTripsEightBitCodes) {
  for (std::size_t channels = 1; channels <= 4; ++channels) {
    std::vector<Transfer> transfers(channels, Transfer::gamma22);
    if (channels % 2 == 0) transfers.back() = Transfer::linear;  // gray+alpha, RGBA
    std::vector<uint8_t> in(256 * channels);
    for (std::size_t i = 0; i < in.size(); ++i) in[i] = uint8_t(i * 7 + i / channels);
    std::vector<float> decoded(in.size());
    decode_pixels(std::span<const uint8_t>(in), decoded, transfers);
    std::vector<uint8_t> back(in.size());
    encode_pixels(decoded, back, transfers);
    EXPECT_EQ(back, in) << channels << " channels";
  }
}

TEST(Pixels, LargeBuffersMatchThePerSampleFunctions) {
  const std::size_t pixels = 300000;  // many TBB tasks
  std::mt19937 rng(3);
  std::vector<uint16_t> codes(pixels * 4);
  for (auto& c : codes) c = uint16_t(rng());
  std::vector<float> decoded(codes.size());
  decode_pixels(std::span<const uint16_t>(codes), decoded, kRgba);
  std::vector<float> encoded(codes.size());
  encode_pixels(std::span<const float>(decoded), encoded, kRgba);
  std::vector<uint16_t> requantized(codes.size());
  encode_pixels(decoded, requantized, kRgba);
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const Transfer t = kRgba[i % 4];
    ASSERT_EQ(decoded[i], decode_table(t, 16)[codes[i]]) << i;
    ASSERT_EQ(encoded[i], t == Transfer::linear ? decoded[i] : encoded_from_linear_fast(t, decoded[i])) << i;
    ASSERT_EQ(requantized[i], codes[i]) << i;
  }
}

TEST(Pixels, HalfAndFloatDecodeAgree) {
  std::vector<uint16_t> halves;
  std::vector<float> floats;
  for (float v : {0.0f, 0.001f, 0.04045f, 0.25f, 0.5f, 1.0f, 4.0f, -0.5f}) {
    const Imath::half h(v);
    halves.push_back(h.bits());
    floats.push_back(float(h));
  }
  const std::vector<Transfer> gray(1, Transfer::srgb);
  std::vector<float> from_half(halves.size()), from_float(floats.size());
  decode_half_pixels(halves, from_half, gray);
  decode_pixels(std::span<const float>(floats), from_float, gray);
  for (std::size_t i = 0; i < halves.size(); ++i) {
    EXPECT_EQ(from_half[i], float(linear_from_encoded(Transfer::srgb, floats[i])));
    EXPECT_NEAR(from_float[i], from_half[i], 1e-7f * std::abs(from_half[i]));
  }
}

}  // namespace
}  // namespace matbake::color
