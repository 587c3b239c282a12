// Delivery: sizes, resampling, mip chains (normals, alpha coverage) and the KTX2 container, against
// closed forms and float64 sums; the encoder's part where basisu is installed.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>

#include "lib/src/delivery/encode.hpp"
#include "lib/src/delivery/encode_cache.hpp"
#include "lib/src/delivery/level_error.hpp"
#include "matbake/color.hpp"
#include "matbake/delivery.hpp"
#include "matbake/ktx2.hpp"
#include "support/basisu.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::delivery {
namespace {
namespace fs = std::filesystem;

image::Image make_image(int width, int height, int channels, const std::function<float(int x, int y, int c)>& value) {
  image::Image im;
  im.width = width, im.height = height, im.channels = channels;
  im.alpha_channel = channels == 4 ? 3 : channels == 2 ? 1 : -1;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) im.pixels.push_back(value(x, y, c));
    }
  }
  return im;
}

float at(const image::Image& im, int x, int y, int c) {
  return im.pixels[(std::size_t(y) * std::size_t(im.width) + std::size_t(x)) * std::size_t(im.channels) + std::size_t(c)];
}

TEST(DeliverySizes, ScaleLimitAndRoundingNeverAboveTheSource) {
  const auto size = [](Size s, ClassOptions o, Rounding r, std::optional<int> needed = {}) { return delivered_size(s, o, r, needed); };
  EXPECT_EQ(size({2048, 2048}, {}, Rounding::multiple_of_4), (Size{2048, 2048}));
  EXPECT_EQ(size({1000, 500}, {.max_size = 512}, Rounding::multiple_of_4), (Size{512, 256}));
  EXPECT_EQ(size({1000, 500}, {.scale = 0.5}, Rounding::multiple_of_4), (Size{500, 252}));
  EXPECT_EQ(size({1000, 500}, {.scale = 0.5}, Rounding::none), (Size{500, 250}));
  // Power of two: nearest in ratio, but never above the largest power of two within the source.
  EXPECT_EQ(size({1000, 600}, {}, Rounding::power_of_two), (Size{512, 512}));
  EXPECT_EQ(size({2048, 1024}, {.scale = 0.7}, Rounding::power_of_two), (Size{1024, 512}));
  EXPECT_EQ(size({2048, 1024}, {.scale = 0.75}, Rounding::power_of_two), (Size{2048, 1024}));
  // Sides of 1 and 2 stay (KHR_texture_basisu allows them); 3 becomes 2; 5 becomes 4.
  EXPECT_EQ(size({3, 1}, {}, Rounding::multiple_of_4), (Size{2, 1}));
  EXPECT_EQ(size({5, 2}, {}, Rounding::multiple_of_4), (Size{4, 2}));
  // The texel density's need and max_size: the smaller wins.
  EXPECT_EQ(size({1024, 1024}, {.max_size = 512}, Rounding::multiple_of_4, 300), (Size{300, 300}));
  EXPECT_EQ(size({1024, 1024}, {.max_size = 256}, Rounding::multiple_of_4, 300), (Size{256, 256}));
  EXPECT_EQ(size({1024, 1024}, {}, Rounding::multiple_of_4, 4096), (Size{1024, 1024}));
}

// A 2 × 1 quad (two triangles of world area 1) mapped onto UV [0, 1] × [0, 0.5] (UV area 0.25 each):
// a square texture of side L gives it sqrt(0.25 L² / 1) = L / 2 texels per unit, so 100 texels per
// unit need L = 200; a 2:1 texture (H = L / 2) gives L / (2√2), so L = 282.8 → 283.
TEST(DeliverySizes, TexelDensityOfAQuadOfKnownAreas) {
  const std::vector<MappedTriangle> quad{{1, 0.25}, {1, 0.25}};
  EXPECT_EQ(needed_side(quad, {1024, 1024}, 100), 200);
  EXPECT_EQ(needed_side(quad, {1024, 512}, 100), 283);
  EXPECT_EQ(needed_side(quad, {512, 1024}, 100), 283);
  EXPECT_EQ(delivered_size({1024, 512}, {}, Rounding::multiple_of_4, 283), (Size{284, 140}));
  // Triangles without UV area (or world area) have no density; none at all: no need.
  EXPECT_EQ(needed_side({{1, 0}, {0, 0.5}}, {1024, 1024}, 100), std::nullopt);
  // The area-weighted 95th percentile: a stretched triangle of 4% of the area is not served, one of
  // 6% is. (Needs: 100 · sqrt(w / u): 200 for the large one, 1000 for the small one.)
  EXPECT_EQ(needed_side({{0.96, 0.24}, {0.04, 0.0004}}, {64, 64}, 100), 200);
  EXPECT_EQ(needed_side({{0.94, 0.235}, {0.06, 0.0006}}, {64, 64}, 100), 1000);
}

TEST(DeliverySizes, MipChainDownToOneTexel) {
  EXPECT_EQ(mip_sizes({5, 3}), (std::vector<Size>{{5, 3}, {2, 1}, {1, 1}}));
  EXPECT_EQ(mip_sizes({1, 1}), (std::vector<Size>{{1, 1}}));
  EXPECT_EQ(mip_sizes({256, 64}).size(), 9u);
  EXPECT_EQ(mip_sizes({256, 64}).back(), (Size{1, 1}));
}

// A constant stays itself and a fine checkerboard of 0 and 1 averages to exactly 0.5, for every
// filter, wrap and ratio (the filter's weights sum to 1 and are symmetric about each output texel).
TEST(DeliveryResample, ConstantsStayAndACheckerboardAveragesToOneHalf) {
  const image::Image constant = make_image(24, 16, 2, [](int, int, int c) { return c == 0 ? 0.3f : 0.8f; });
  const image::Image checker = make_image(32, 32, 1, [](int x, int y, int) { return float((x + y) % 2); });
  for (Filter f : {Filter::kaiser, Filter::box}) {
    for (Wrap w : {Wrap::repeat, Wrap::clamp_to_edge, Wrap::mirrored_repeat}) {
      const Sampling s{f, w, w};
      const image::Image c = resample(constant, {7, 5}, s);
      for (std::size_t i = 0; i < c.pixels.size(); ++i) EXPECT_NEAR(c.pixels[i], i % 2 ? 0.8 : 0.3, 1e-6);
      if (w != Wrap::repeat) continue;  // an even-sized checkerboard repeats as itself
      for (Size size : {Size{16, 16}, Size{8, 4}, Size{1, 1}}) {
        const image::Image half = resample(checker, size, s);
        for (float v : half.pixels) EXPECT_NEAR(v, 0.5, 1e-6) << int(f) << " " << size.width;
      }
    }
  }
}

// A symmetric filter whose weights sum to 1 keeps a linear ramp: away from the edges each output
// texel is the ramp at its centre, in float64. Exactly so for a whole ratio (the taps lie
// symmetrically about the centre); for 96 → 20 they do not, and the ramp is kept within 1% of one
// output texel's step.
TEST(DeliveryResample, KeepsALinearRampAwayFromTheEdges) {
  const image::Image ramp = make_image(96, 4, 1, [](int x, int, int) { return float(0.01 * (x + 0.5)); });
  for (Filter f : {Filter::kaiser, Filter::box}) {
    for (int width : {48, 32, 20}) {
      const image::Image out = resample(ramp, {width, 4}, {f, Wrap::clamp_to_edge, Wrap::clamp_to_edge});
      const double step = 96.0 / width;
      const double tolerance = 96 % width == 0 ? 2e-6 : 0.01 * 0.01 * step;
      for (int x = 4; x < width - 4; ++x) {  // the Kaiser window reaches 3 output texels
        EXPECT_NEAR(at(out, x, 0, 0), 0.01 * (x + 0.5) * step, tolerance) << width << " " << x;
      }
    }
  }
}

// The box filter of a whole ratio is the mean of each block, as float64 sums give it.
TEST(DeliveryResample, BoxOfAWholeRatioIsTheBlockMean) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  const image::Image noise = make_image(12, 8, 3, [&](int, int, int) { return u(rng); });
  const image::Image out = resample(noise, {3, 2}, {Filter::box, Wrap::repeat, Wrap::repeat});
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        for (int j = 0; j < 4; ++j) {
          for (int i = 0; i < 4; ++i) sum += at(noise, 4 * x + i, 4 * y + j, c);
        }
        EXPECT_NEAR(at(out, x, y, c), sum / 16, 1e-6);
      }
    }
  }
}

// Edges: a sampler's wrap mode is the image extended past its edge. Resampling the extended image
// (five tiles, repeated, mirrored or edge-padded) and keeping its middle tile gives the same texels as
// resampling the image itself with that wrap mode, where no read reaches the extension's own edge.
TEST(DeliveryResample, EdgesFollowTheWrapMode) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0, 1);
  const image::Image tile = make_image(8, 1, 1, [&](int, int, int) { return u(rng); });
  for (Wrap wrap : {Wrap::repeat, Wrap::mirrored_repeat, Wrap::clamp_to_edge}) {
    const image::Image extended = make_image(40, 1, 1, [&](int x, int, int) {
      const int copy = x / 8, i = x % 8;
      if (wrap == Wrap::clamp_to_edge) return at(tile, std::clamp(x - 16, 0, 7), 0, 0);
      return at(tile, wrap == Wrap::mirrored_repeat && copy % 2 == 1 ? 7 - i : i, 0, 0);
    });
    for (Filter f : {Filter::kaiser, Filter::box}) {
      const image::Image whole = resample(extended, {10, 1}, {f, Wrap::clamp_to_edge, Wrap::clamp_to_edge});
      const image::Image own = resample(tile, {2, 1}, {f, wrap, wrap});
      EXPECT_NEAR(at(own, 0, 0, 0), at(whole, 4, 0, 0), 1e-6) << int(wrap) << " " << int(f);
      EXPECT_NEAR(at(own, 1, 0, 0), at(whole, 5, 0, 0), 1e-6) << int(wrap) << " " << int(f);
    }
  }
}

double length_of(const image::Image& im, std::size_t p) {
  const float* t = &im.pixels[p * std::size_t(im.channels)];
  double s = 0;
  for (int c = 0; c < 3; ++c) s += (2.0 * t[c] - 1) * (2.0 * t[c] - 1);
  return std::sqrt(s);
}

TEST(DeliveryMips, NormalsAreUnitLengthAtEveryLevel) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  const image::Image normals = make_image(64, 32, 3, [&](int, int, int c) {
    return float(c == 2 ? 0.5 + 0.5 * std::abs(g(rng)) : 0.5 + 0.2 * g(rng));  // not unit length: as 8-bit maps are
  });
  for (Filter f : {Filter::kaiser, Filter::box}) {
    const auto levels = mip_chain(normals, {64, 32}, {TextureClass::normal, {f, Wrap::repeat, Wrap::repeat}, {}});
    ASSERT_EQ(levels.size(), 7u);
    for (const image::Image& l : levels) {
      for (std::size_t p = 0; p < std::size_t(l.width * l.height); ++p) EXPECT_NEAR(length_of(l, p), 1.0, 1e-3);
    }
  }
  // A zero vector (the flat grey of an empty map) becomes +Z.
  const auto flat = mip_chain(make_image(4, 4, 3, [](int, int, int) { return 0.5f; }), {4, 4},
                              {TextureClass::normal, {}, {}}, false);
  EXPECT_FLOAT_EQ(at(flat[0], 1, 1, 2), 1.0f);
  EXPECT_FLOAT_EQ(at(flat[0], 1, 1, 0), 0.5f);
}

// Foliage: one opaque texel in four (a sparse lattice of leaves). Plain filtering leaves a level-1
// alpha of 0.25 everywhere, below a 0.5 cutoff: the leaves vanish. With the coverage kept, each
// level renders as much as the source: 25% within one texel's share.
TEST(DeliveryMips, AlphaCoverageOfAMaskMaterialIsKeptAtEveryLevel) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 1);
  const image::Image leaves = make_image(64, 64, 4, [&](int x, int y, int c) {
    if (c < 3) return 0.3f;
    return (x % 2 == 0 && y % 2 == 0) ? 0.7f + 0.3f * u(rng) : 0.2f * u(rng);
  });
  const float cutoff = 0.5f;
  const double source = alpha_coverage(leaves, cutoff);
  EXPECT_NEAR(source, 0.25, 1e-12);
  for (const std::optional<float> measured : {std::optional<float>{}, std::optional<float>{cutoff}}) {
    const auto plain = mip_chain(leaves, {64, 64}, {TextureClass::colour, {}, measured});  // kept only when asked
    EXPECT_LT(alpha_coverage(plain[1], cutoff), 0.05);
  }
  for (Filter f : {Filter::kaiser, Filter::box}) {
    const auto kept = mip_chain(leaves, {64, 64}, {TextureClass::colour, {f, Wrap::repeat, Wrap::repeat}, cutoff, true});
    for (const image::Image& l : kept) {
      const double texels = double(l.width) * l.height;
      EXPECT_NEAR(alpha_coverage(l, cutoff), source, std::max(0.01, 0.5 / texels) + 1e-12) << l.width;
    }
  }
  // A level of fewer texels than the coverage can split: 1×1 renders all or nothing, the nearer.
  const auto tiny = mip_chain(leaves, {64, 64}, {TextureClass::colour, {}, 0.5f, true});
  EXPECT_EQ(alpha_coverage(tiny.back(), cutoff), 0.0);
}

TEST(DeliveryMips, EveryLevelComesFromTheSource) {
  // Level 2 of a 16-wide box chain is the mean of 4-texel blocks of the source, not a mean of means
  // of level 1 filtered with the Kaiser window (which would differ on noise).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  const image::Image noise = make_image(16, 16, 1, [&](int, int, int) { return u(rng); });
  const auto levels = mip_chain(noise, {16, 16}, {TextureClass::data, {Filter::kaiser, Wrap::repeat, Wrap::repeat}, {}});
  const image::Image direct = resample(noise, {4, 4}, {Filter::kaiser, Wrap::repeat, Wrap::repeat});
  EXPECT_EQ(levels[2].pixels, direct.pixels);
  const image::Image chained = resample(levels[1], {4, 4}, {Filter::kaiser, Wrap::repeat, Wrap::repeat});
  EXPECT_NE(levels[2].pixels, chained.pixels);
}

std::vector<unsigned char> bytes_of(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<unsigned char> out(n);
  for (auto& b : out) b = static_cast<unsigned char>(rng());
  return out;
}

TEST(Ktx2, AUastcFileReadsBackFieldByField) {
  for (int zstd : {0, 9}) {
    SCOPED_TRACE(zstd);
    ktx2::UastcFile file{.width = 20, .height = 12, .transfer = ktx2::kTransferSRGB, .channel = ktx2::kUastcRGBA, .levels = {},
                         .zstd = zstd > 0, .writer = "matbake test"};
    std::vector<std::vector<unsigned char>> raw;
    for (Size s : mip_sizes({20, 12})) {
      raw.push_back(bytes_of(16 * std::size_t((s.width + 3) / 4) * std::size_t((s.height + 3) / 4), unsigned(s.width)));
      file.levels.push_back(*ktx2::uastc_level(raw.back(), zstd));
    }
    auto bytes = ktx2::write_uastc(file);
    ASSERT_TRUE(bytes) << bytes.error().to_string();
    auto t = ktx2::read(*bytes, "t.ktx2");
    ASSERT_TRUE(t) << t.error().to_string();
    EXPECT_EQ(t->vk_format, 0u);
    EXPECT_EQ(t->type_size, 1u);
    EXPECT_EQ(t->width, 20u);
    EXPECT_EQ(t->height, 12u);
    EXPECT_EQ(t->supercompression, zstd ? ktx2::kSupercompressionZstd : ktx2::kSupercompressionNone);
    ASSERT_EQ(t->levels.size(), 5u);  // 20×12, 10×6, 5×3, 2×1, 1×1
    EXPECT_EQ(t->descriptor.model, ktx2::kModelUASTC);
    EXPECT_EQ(t->descriptor.transfer, ktx2::kTransferSRGB);
    EXPECT_EQ(t->descriptor.primaries, 1);
    EXPECT_EQ(t->descriptor.block_width, 4);
    EXPECT_EQ(t->descriptor.block_height, 4);
    EXPECT_EQ(t->descriptor.bytes_plane0, zstd ? 0 : 16);
    EXPECT_EQ(t->descriptor.channels, (std::vector<std::uint8_t>{ktx2::kUastcRGBA}));
    EXPECT_EQ(t->dfd, ktx2::uastc_descriptor(ktx2::kTransferSRGB, ktx2::kUastcRGBA, zstd > 0));
    EXPECT_EQ(t->key_values, (std::vector<std::pair<std::string, std::string>>{{"KTXwriter", "matbake test"}}));
    std::uint64_t previous_offset = ~0ull;
    for (std::size_t l = 0; l < 5; ++l) {
      auto data = ktx2::level_data(*t, l, "t.ktx2");
      ASSERT_TRUE(data) << data.error().to_string();
      EXPECT_EQ(*data, raw[l]);
      EXPECT_EQ(t->levels[l].uncompressed_length, raw[l].size());
      // Smallest level first in the file; uncompressed levels on 16-byte boundaries.
      std::uint64_t offset;
      std::memcpy(&offset, bytes->data() + 80 + 24 * l, 8);
      EXPECT_LT(offset, previous_offset);
      previous_offset = offset;
      if (!zstd) {
        EXPECT_EQ(offset % 16, 0u);
      }
    }
  }
}

TEST(Ktx2, DamagedFilesAreRefusedWithTheirName) {
  ktx2::UastcFile file{.width = 4, .height = 4, .levels = {*ktx2::uastc_level(bytes_of(16, 1), 0)}, .writer = "w"};
  auto bytes = ktx2::write_uastc(file);
  ASSERT_TRUE(bytes);
  const auto refused = [](std::vector<unsigned char> b) {
    auto t = ktx2::read(b, "bad.ktx2");
    return t ? std::string("read") : t.error().to_string();
  };
  EXPECT_EQ(refused({bytes->begin(), bytes->begin() + 40}), "bad.ktx2: not a KTX2 file (no KTX 20 identifier)");
  std::vector<unsigned char> past = *bytes;
  past[80] = 0xFF, past[81] = 0xFF;  // level 0's offset
  EXPECT_EQ(refused(past), "bad.ktx2: KTX2 level 0 lies past the end of the file");
  std::vector<unsigned char> levels = *bytes;
  levels[40] = 200;
  EXPECT_EQ(refused(levels), "bad.ktx2: KTX2 file declares 200 levels");
  std::vector<unsigned char> cube = *bytes;
  cube[36] = 6;
  EXPECT_EQ(refused(cube), "bad.ktx2: KTX2 file is not a plain 2D texture (depth, layers or faces)");
  std::vector<unsigned char> huge = *bytes;  // 4 × 2^31: refused before any level is read
  huge[27] = 0x80;
  EXPECT_EQ(refused(huge).rfind("bad.ktx2: ", 0), 0u);
  EXPECT_NE(refused(huge), "read");
  // A zstd level whose declared length its frame does not have (found by fuzzing: 4 GB allocated).
  ktx2::UastcFile zstd{.width = 4, .height = 4, .levels = {*ktx2::uastc_level(bytes_of(16, 2), 3)}, .zstd = true, .writer = "w"};
  auto packed = ktx2::write_uastc(zstd);
  ASSERT_TRUE(packed);
  std::vector<unsigned char> longer = *packed;
  longer[80 + 16] = 32;  // uncompressedByteLength of level 0: 32 of a 16-byte level
  auto t = ktx2::read(longer, "bad.ktx2");
  ASSERT_TRUE(t);
  auto level = ktx2::level_data(*t, 0, "bad.ktx2");
  ASSERT_FALSE(level);
  EXPECT_EQ(level.error().to_string(), "bad.ktx2: KTX2 level 0 declares a length its size or its zstd frame does not have");
}

// ---- Level error (level_error.hpp): closed forms of one level --------------------------------------

// A decoded level as basisu's PNG reads: 8-bit codes / 255, `channels` of them per texel.
image::Image decoded_codes(int width, int height, int channels, const std::function<int(int x, int y, int c)>& code) {
  return make_image(width, height, channels, [&](int x, int y, int c) { return float(code(x, y, c)) / 255.0f; });
}

// Colour is compared in the sRGB codes the encoder read: a level whose every code is one off decodes
// at PSNR 20·log10(255) = 48.13 dB; an exact one at 99 (identical); a file without alpha (an RGB PNG)
// compares RGB only.
TEST(DeliveryLevelError, ColourCodesOneOffAreTwentyLogTwoFiftyFive) {
  const EncodeRequest colour{.texture_class = TextureClass::colour};
  const float linear = float(color::linear_from_encoded(color::Transfer::srgb, 100.0 / 255.0));
  const image::Image made = make_image(8, 4, 3, [&](int, int, int) { return linear; });
  ASSERT_EQ(color::quantize(color::Transfer::srgb, 8, linear), 100);
  const LevelError off = compare_level(made, decoded_codes(8, 4, 3, [](int x, int, int) { return x % 2 ? 101 : 99; }), {}, colour);
  EXPECT_NEAR(off.psnr, 20 * std::log10(255.0), 1e-9);
  EXPECT_EQ(compare_level(made, decoded_codes(8, 4, 3, [](int, int, int) { return 100; }), {}, colour).psnr, kIdenticalPsnr);
  // Data: linear codes, the alpha compared when the file has it (a texel's alpha 255 where the level has none).
  const EncodeRequest data_rgba{.texture_class = TextureClass::data, .alpha = true};
  const image::Image half = make_image(8, 4, 3, [](int, int, int) { return 0.5f; });  // code 128 (127.5 rounds up)
  const LevelError alpha_off = compare_level(half, decoded_codes(8, 4, 4, [](int, int, int c) { return c < 3 ? 128 : 245; }), {}, data_rgba);
  EXPECT_NEAR(alpha_off.psnr, 10 * std::log10(255.0 * 255.0 * 4 / 100.0), 1e-9);  // 10 codes in one channel of four
}

// Normal maps: the angle between the normals the codes hold, per texel, mean and max; a MASK
// texture's decoded coverage is that of the decoded alpha against the cutoff.
TEST(DeliveryLevelError, NormalAnglesAndDecodedCoverageAreThoseOfTheCodes) {
  const EncodeRequest normal{.texture_class = TextureClass::normal};
  const MipRequest normal_mips{TextureClass::normal};
  // Made: +Z exactly (codes 128, 128, 255 hold (1/255, 1/255, 1) before renormalising).
  const image::Image made = make_image(4, 4, 3, [](int, int, int c) { return c == 2 ? 1.0f : 128.0f / 255.0f; });
  // Decoded: half the texels tilted in x to code 200, half as made.
  const image::Image decoded = decoded_codes(4, 4, 3, [](int x, int, int c) { return c == 2 ? 255 : c == 0 && x < 2 ? 200 : 128; });
  const auto unit = [](double x, double y, double z) {
    const double l = std::hypot(x, y, z);
    return std::array<double, 3>{x / l, y / l, z / l};
  };
  const auto a = unit(2 * 128 / 255.0 - 1, 2 * 128 / 255.0 - 1, 1), b = unit(2 * 200 / 255.0 - 1, 2 * 128 / 255.0 - 1, 1);
  const double cross = std::hypot(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
  const double tilt = std::atan2(cross, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * 180 / std::numbers::pi;
  const LevelError e = compare_level(made, decoded, normal_mips, normal);
  EXPECT_NEAR(e.max_angle, tilt, 1e-9);
  EXPECT_NEAR(e.mean_angle, tilt / 2, 1e-9);
  EXPECT_NEAR(e.psnr, 10 * std::log10(255.0 * 255.0 * 6 / (72.0 * 72.0)), 1e-9);  // 72 codes in one of 3 channels, half the texels
  EXPECT_EQ(compare_level(made, made, {TextureClass::data}, {.texture_class = TextureClass::data}).mean_angle, 0);

  const MipRequest mask{TextureClass::colour, {}, 0.5f};
  const EncodeRequest rgba{.texture_class = TextureClass::colour, .alpha = true};
  const image::Image leaves = make_image(4, 4, 4, [](int x, int, int c) { return c < 3 ? 0.2f : x < 1 ? 1.0f : 0.0f; });
  // Decoded: alpha 128 (≥ 0.5 in 8 bits: 127.5 rounds up) in three columns of four, 127 in the last.
  const LevelError m = compare_level(leaves, decoded_codes(4, 4, 4, [](int x, int, int c) { return c < 3 ? 124 : x < 3 ? 128 : 127; }), mask, rgba);
  EXPECT_DOUBLE_EQ(m.coverage, 0.75);
}

// ---- With the encoder ------------------------------------------------------------------------------

// The encoder, or a reason to skip (support/basisu.hpp).
std::optional<Encoder> encoder_or_skip(std::string& why) {
  const std::string path = test::basisu_for_tests(why);
  if (path.empty()) return std::nullopt;
  setenv("MATBAKE_BASISU", path.c_str(), 1);
  auto e = find_encoder();
  if (!e) why = e.error().to_string();
  return e ? std::optional(*e) : std::nullopt;
}

// The mean squared difference in 8-bit codes of a linear level's channel and its decoded codes.
double squared_error(const image::Image& a, const test::RawImage& b, int channel) {
  double sum = 0;
  const std::size_t pixels = std::size_t(a.width) * std::size_t(a.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    const double d = std::round(std::clamp(a.pixels[p * std::size_t(a.channels) + std::size_t(channel)], 0.0f, 1.0f) * 255) -
                     b.samples[p * std::size_t(b.channels) + std::size_t(channel)];
    sum += d * d;
  }
  return sum / double(pixels);
}

double psnr(const image::Image& a, const test::RawImage& b, int channel) {
  const double mean_squared = squared_error(a, b, channel);
  return mean_squared == 0 ? 99 : 10 * std::log10(255.0 * 255.0 / mean_squared);
}

// A data texture's UASTC chain through basisu and our container: basisu itself validates the file
// and unpacks every level, each within its PSNR bound of the chain matbake made; the DFD is the
// one basisu writes for the same content.
TEST(DeliveryEncoder, AUastcChainAssembledHereIsValidAndDecodesNearItsLevels) {
  std::string why;
  const auto encoder = encoder_or_skip(why);
  if (!encoder) GTEST_SKIP() << why;
  test::TempDir dir;
  const image::Image smooth = make_image(32, 16, 3, [](int x, int y, int c) {
    return float(0.5 + 0.4 * std::sin(0.07 * x + 0.3 * c) * std::cos(0.09 * y));
  });
  const auto levels = mip_chain(smooth, {32, 16}, {TextureClass::data, {}, {}});
  EncodeRequest request{.texture_class = TextureClass::data, .options = {.codec = Codec::uastc}, .scratch = dir.path() / "t.ktx2"};
  auto encoded = encode_texture(*encoder, smooth, {32, 16}, {TextureClass::data, {}, {}}, request, "matbake test");
  ASSERT_TRUE(encoded) << encoded.error().to_string();
  const std::vector<unsigned char>* bytes = &encoded->file;
  auto read = ktx2::read(*bytes, "chain.ktx2");
  ASSERT_TRUE(read);
  EXPECT_EQ(read->dfd, ktx2::uastc_descriptor(ktx2::kTransferLinear, ktx2::kUastcRGB, true));
  for (std::size_t l = 0; l < levels.size(); ++l) {
    EXPECT_EQ(read->levels[l].uncompressed_length,
              16 * std::size_t((levels[l].width + 3) / 4) * std::size_t((levels[l].height + 3) / 4));
  }
  const fs::path path = dir.path() / "chain.ktx2";
  test::write_bytes(path, std::string(bytes->begin(), bytes->end()));
  const test::RunResult validated = test::run(encoder->program.string(), {"-validate", "-file", path.string()});
  EXPECT_EQ(validated.exit_code, 0) << validated.out << validated.err;
  EXPECT_EQ(test::list_folder(dir.path()), (std::vector<std::string>{"chain.ktx2"}));  // no scratch left
  const test::RunResult unpacked = test::run("/bin/sh", {"-c", "cd " + dir.path().string() + " && " + encoder->program.string() +
                                                                   " -unpack -no_ktx -format_only 6 -file chain.ktx2 >/dev/null"});
  ASSERT_EQ(unpacked.exit_code, 0) << unpacked.err;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const fs::path level = dir.path() / ("chain_unpacked_rgba_BC7_RGBA_" + std::to_string(l) + "_0000.png");
    ASSERT_TRUE(fs::exists(level)) << level << "\n" << test::list_folder(dir.path()).size();
    const test::RawImage decoded = test::read_raw(level);
    // UASTC level 2 on this content: 44–49 dB at level 0, 31–39 dB on the 8×4 and 4×2 levels (a
    // block spans a larger part of the wave there).
    for (int c = 0; c < 3; ++c) EXPECT_GT(psnr(levels[l], decoded, c), l == 0 ? 42 : 30) << "level " << l << " channel " << c;
    // What delivery measured of the same file is the PSNR of the three channels together: the mean
    // of their squared errors.
    double mean_squared = 0;
    for (int c = 0; c < 3; ++c) mean_squared += squared_error(levels[l], decoded, c) / 3;
    ASSERT_EQ(encoded->level_error.size(), levels.size());
    const double expected = mean_squared == 0 ? kIdenticalPsnr : 10 * std::log10(255.0 * 255.0 / mean_squared);
    EXPECT_NEAR(encoded->level_error[l].psnr, expected, 1e-9) << "level " << l;
  }
  request.measure_levels = false;  // off: the same file, nothing measured
  auto unmeasured = encode_texture(*encoder, smooth, {32, 16}, {TextureClass::data, {}, {}}, request, "matbake test");
  ASSERT_TRUE(unmeasured) << unmeasured.error().to_string();
  EXPECT_TRUE(unmeasured->file == encoded->file);
  EXPECT_TRUE(unmeasured->level_error.empty());
  EXPECT_EQ(test::list_folder(dir.path()).size(), 1 + 3 * levels.size()) << "the file and the test's own PNGs, nothing else";
}


// The key changes with every input of an encode (a texel, the size, a setting, the versions) and with
// nothing else (a copy of the same pixels, other max_size/scale that give the same level 0).
TEST(EncodeCache, TheKeyFollowsWhatTheBytesDependOn) {
  const image::Image source = make_image(8, 8, 3, [](int x, int y, int c) { return float(x + 2 * y + c) / 32.0f; });
  const MipRequest mips{TextureClass::data};
  const EncodeRequest request{.texture_class = TextureClass::data, .options = {.codec = Codec::uastc}};
  const std::string writer = "matbake 0.2.0 / basisu 1.16.4";
  const std::string key = encode_key(source, {8, 8}, mips, request, writer);
  ASSERT_EQ(key.size(), 32u);
  image::Image copy = source;
  EncodeRequest same_level0 = request;
  same_level0.options.max_size = 8;
  same_level0.scratch = "/elsewhere/name.ktx2";
  same_level0.threads = 7;
  EXPECT_EQ(encode_key(copy, {8, 8}, mips, same_level0, writer), key);
  std::set<std::string> keys{key};
  copy.pixels[17] += 1.0f / 255;
  keys.insert(encode_key(copy, {8, 8}, mips, request, writer));
  keys.insert(encode_key(source, {4, 4}, mips, request, writer));
  keys.insert(encode_key(source, {8, 8}, {TextureClass::data, {.filter = Filter::kaiser}}, request, writer));
  keys.insert(encode_key(source, {8, 8}, {TextureClass::data, {.wrap_s = Wrap::clamp_to_edge}}, request, writer));
  keys.insert(encode_key(source, {8, 8}, {TextureClass::data, {}, 0.5f}, request, writer));
  keys.insert(encode_key(source, {8, 8}, {TextureClass::data, {}, 0.5f, true}, request, writer));
  for (auto change : std::vector<std::function<void(EncodeRequest&)>>{
           [](EncodeRequest& r) { r.options.uastc_level = 3; }, [](EncodeRequest& r) { r.options.uastc_rdo = 0.5; },
           [](EncodeRequest& r) {
             r.options.uastc_rdo = 0.5;
             r.options.uastc_rdo_dictionary = 1024;
           },
           [](EncodeRequest& r) { r.options.zstd = 3; }, [](EncodeRequest& r) { r.mipmaps = false; },
           [](EncodeRequest& r) { r.alpha = true; }, [](EncodeRequest& r) { r.texture_class = TextureClass::normal; },
           [](EncodeRequest& r) { r.options.codec = Codec::etc1s; }, [](EncodeRequest& r) { r.measure_levels = false; }}) {
    EncodeRequest changed = request;
    change(changed);
    keys.insert(encode_key(source, {8, 8}, mips, changed, writer));
  }
  keys.insert(encode_key(source, {8, 8}, mips, request, "matbake 0.2.0 / basisu 1.16.5"));
  EXPECT_EQ(keys.size(), 17u);  // each of the 16 changes a key of its own
}

// Eviction removes the least recently used entries until the rest fit, and nothing that is not an
// entry: a file named as one without its header, a link named as one (its target untouched), other
// files.
TEST(EncodeCache, EvictionRemovesTheLeastRecentlyUsedEntriesAndOnlyEntries) {
  test::TempDir dir;
  const fs::path cache = dir / "encode-cache";
  fs::create_directories(cache);
  const std::string entry_head = "matbake encoded texture 1\n", current_head = "matbake encoded texture 2\n";
  const auto entry = [&](char digit, int age_seconds, const std::string& head) {
    const fs::path file = cache / (std::string(32, digit) + ".ktx2e");
    test::write_bytes(file, head + std::string(1000 - head.size(), 'x'));
    const struct timespec times[2] = {{1700000000 - age_seconds, 0}, {1700000000 - age_seconds, 0}};
    EXPECT_EQ(::utimensat(AT_FDCWD, file.c_str(), times, AT_SYMLINK_NOFOLLOW), 0);
    return file;
  };
  const fs::path oldest = entry('0', 50, entry_head), older = entry('1', 40, entry_head), not_one = entry('2', 45, "something else");
  const fs::path newer = entry('3', 20, current_head), newest = entry('4', 10, entry_head);
  test::write_bytes(dir / "outside.txt", "not matbake's");
  fs::create_symlink(dir / "outside.txt", cache / (std::string(32, '5') + ".ktx2e"));
  test::write_bytes(cache / "notes.txt", std::string(5000, 'n'));
  // Five regular files named as entries, 5000 bytes: the oldest entries go, of this version's format
  // or an earlier one's (the one without a header is counted and kept), until 2000 remain.
  evict_encoded(cache, 2500);
  EXPECT_FALSE(fs::exists(oldest));
  EXPECT_FALSE(fs::exists(older));
  EXPECT_FALSE(fs::exists(newer));
  EXPECT_TRUE(fs::exists(not_one));
  EXPECT_TRUE(fs::exists(newest));
  EXPECT_TRUE(fs::is_symlink(cache / (std::string(32, '5') + ".ktx2e")));
  EXPECT_EQ(test::read_bytes(dir / "outside.txt"), "not matbake's");
  EXPECT_TRUE(fs::exists(cache / "notes.txt"));
  evict_encoded(cache, 1 << 20);  // within the limit: nothing goes
  EXPECT_TRUE(fs::exists(newest));
}

// PNG and WebP files (resized textures) go through the cache as KTX2 files do: kept, read back the
// same, and ignored (made again) where the entry is not a file of the asked size or is damaged.
TEST(EncodeCache, PngAndWebpEntriesAreKeptAndCheckedOnTheWayBack) {
  test::TempDir dir;
  const EncodeCache cache{dir / "encode-cache", 1 << 20};
  const image::Image texture = make_image(12, 8, 3, [](int x, int y, int c) { return float((x * 7 + y * 3 + c) % 11) / 10.0f; });
  for (const std::string format : {"png", "webp"}) {
    SCOPED_TRACE(format);
    int made = 0;
    const auto encode = [&]() -> Result<Encoded> {
      ++made;
      auto bytes = image::encode_image(texture, "t." + format, {.type = image::SampleType::u8, .compression = "lossless"});
      if (!bytes) return bytes.error();
      return Encoded{{bytes->begin(), bytes->end()}, 1, {0.25, 0.5}, {{41.5, 0.25, 3.5, 0.5}}};
    };
    const std::string key = made_file_key(texture, {12, 8}, {TextureClass::colour}, format, 6, "matbake test");
    bool reused = true;
    auto first = through_cache(cache, key, {12, 8}, encode, reused);
    ASSERT_TRUE(first) << first.error().to_string();
    EXPECT_FALSE(reused);
    auto second = through_cache(cache, key, {12, 8}, encode, reused);
    ASSERT_TRUE(second) << second.error().to_string();
    EXPECT_TRUE(reused);
    EXPECT_EQ(made, 1);
    EXPECT_TRUE(second->file == first->file);
    EXPECT_EQ(second->coverage, first->coverage);
    EXPECT_EQ(second->level_error, first->level_error);
    EXPECT_TRUE(through_cache(cache, key, {12, 12}, encode, reused));  // not of the asked size: made again
    EXPECT_FALSE(reused);
    const fs::path entry = cache.folder / (key + ".ktx2e");
    fs::resize_file(entry, fs::file_size(entry) - 8);  // its pixels cut short
    EXPECT_TRUE(through_cache(cache, key, {12, 8}, encode, reused));
    EXPECT_FALSE(reused);
    EXPECT_EQ(made, 3);
  }
  EXPECT_NE(made_file_key(texture, {12, 8}, {TextureClass::colour}, "png", 6, "w"),
            made_file_key(texture, {12, 8}, {TextureClass::colour}, "webp", 6, "w"));
  EXPECT_NE(made_file_key(texture, {12, 8}, {TextureClass::colour}, "png", 6, "w"),
            made_file_key(texture, {12, 8}, {TextureClass::colour}, "png", 9, "w"));
}

}  // namespace
}  // namespace matbake::delivery
