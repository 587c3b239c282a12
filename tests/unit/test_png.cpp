// matbake's PNG writer (libdeflate): files that libpng (through OIIO) and our reader read back code
// for code, at every level, layout, depth and odd size; chunks as the PNG spec frames them.
#include <gtest/gtest.h>
#include <zlib.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <span>
#include <random>
#include <string>
#include <vector>

#include "matbake/image.hpp"
#include "support/temp_dir.hpp"

namespace matbake::image {
namespace {

using color::Transfer;

struct Chunk {
  std::string type;
  std::string data;
};

std::uint32_t be32(const std::string& s, std::size_t at) {
  return std::uint32_t(std::uint8_t(s[at])) << 24 | std::uint32_t(std::uint8_t(s[at + 1])) << 16 |
         std::uint32_t(std::uint8_t(s[at + 2])) << 8 | std::uint32_t(std::uint8_t(s[at + 3]));
}

// Splits a PNG into chunks, checking the signature, each length and each CRC (with zlib's crc32,
// not the writer's).
std::vector<Chunk> chunks_of(const std::string& png) {
  std::vector<Chunk> chunks;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  for (std::size_t at = 8; at < png.size();) {
    EXPECT_LE(at + 12, png.size());
    const std::uint32_t length = be32(png, at);
    EXPECT_LE(at + 12 + length, png.size());
    const std::string type_and_data = png.substr(at + 4, 4 + length);
    const auto crc = crc32(0, reinterpret_cast<const Bytef*>(type_and_data.data()), uInt(type_and_data.size()));
    EXPECT_EQ(be32(png, at + 8 + length), crc) << type_and_data.substr(0, 4);
    chunks.push_back({type_and_data.substr(0, 4), type_and_data.substr(4)});
    at += 12 + length;
  }
  return chunks;
}

// OIIO's reader (libpng) on the bytes, through a file.
std::unique_ptr<OIIO::ImageInput> open_in_libpng(const std::string& png, const test::TempDir& dir) {
  const std::filesystem::path path = dir / "libpng.png";
  std::ofstream(path, std::ios::binary) << png;
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  return OIIO::ImageInput::open(path.string(), &config);
}

// Codes as libpng reads them (OIIO, native type).
std::vector<std::uint16_t> libpng_codes(const std::string& png, int& channels, int& bits) {
  test::TempDir dir;
  auto in = open_in_libpng(png, dir);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  channels = spec.nchannels;
  bits = int(spec.format.size()) * 8;
  std::vector<std::uint16_t> codes(spec.image_pixels() * std::size_t(spec.nchannels));
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT16, codes.data()));
  if (bits == 8) {
    for (auto& c : codes) c = std::uint16_t(c / 257);  // OIIO widens 8-bit codes by 257
  }
  return codes;
}

Image image_of_codes(int width, int height, int channels, const std::vector<std::uint16_t>& codes, int max) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.alpha_channel = channels == 2 ? 1 : channels == 4 ? 3 : -1;
  for (std::uint16_t c : codes) image.pixels.push_back(float(double(c) / max));
  return image;
}

// Codes that exercise every filter: smooth ramps (Sub/Up/Average/Paeth win) and noise (None wins).
std::vector<std::uint16_t> test_codes(int width, int height, int channels, int max, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::uint16_t> codes;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < channels; ++c) {
        const bool noisy = (y / 3) % 2 == 1;
        codes.push_back(std::uint16_t(noisy ? rng() % std::uint32_t(max + 1) : (x * 37 + y * 11 + c * 101) % (max + 1)));
      }
    }
  }
  return codes;
}

// An image given band by band (encode_bands) is the same file as the image given whole, for sizes
// of one band, several and a last partial one; each row filled once, with its own rows.
TEST(Png, BandsFilledByTheCallerGiveTheBytesOfTheWholeImage) {
  for (auto [w, h] : {std::pair{5, 3}, std::pair{300, 1000}, std::pair{64, 4097}}) {
    const auto codes = test_codes(w, h, 3, 255, unsigned(w + h));
    const Image image = image_of_codes(w, h, 3, codes, 255);
    WriteOptions options;
    options.type = SampleType::u8;
    options.colour = Transfer::srgb;
    std::vector<int> filled(std::size_t(h), 0);
    std::mutex guard;
    const auto fill = [&](int y, int rows, std::span<float> samples) {
      ASSERT_EQ(samples.size(), std::size_t(w) * std::size_t(rows) * 3u);
      std::copy_n(image.pixels.begin() + std::ptrdiff_t(std::size_t(y) * std::size_t(w) * 3u), samples.size(), samples.begin());
      std::lock_guard lock(guard);
      for (int r = y; r < y + rows; ++r) ++filled[std::size_t(r)];
    };
    auto banded = encode_bands(image, fill, "x.png", options);
    ASSERT_TRUE(banded) << banded.error().to_string();
    EXPECT_TRUE(*banded == encode_image(image, "x.png", options).value()) << w << "x" << h;  // not printed: bytes
    EXPECT_EQ(filled, std::vector<int>(std::size_t(h), 1)) << w << "x" << h;
  }
}

TEST(Png, EveryLayoutDepthLevelAndOddSizeReadsBackCodeForCodeInLibpngAndOurReader) {
  for (int bits : {8, 16}) {
    const int max = (1 << bits) - 1;
    for (int channels = 1; channels <= 4; ++channels) {
      for (auto [w, h] : {std::pair{1, 1}, std::pair{7, 5}, std::pair{1, 9}, std::pair{33, 2}}) {
        const auto codes = test_codes(w, h, channels, max, unsigned(w * 100 + h + channels));
        const Image image = image_of_codes(w, h, channels, codes, max);
        for (int level : {0, 1, 6, 12}) {
          WriteOptions options;
          options.type = bits == 8 ? SampleType::u8 : SampleType::u16;
          options.png_level = level;
          auto png = encode_image(image, "x.png", options);
          ASSERT_TRUE(png) << png.error().to_string();
          const std::string where = std::to_string(bits) + "-bit, " + std::to_string(channels) + " channels, " +
                                    std::to_string(w) + "x" + std::to_string(h) + ", level " + std::to_string(level);
          int read_channels = 0, read_bits = 0;
          EXPECT_EQ(libpng_codes(*png, read_channels, read_bits), codes) << where;
          EXPECT_EQ(read_channels, channels) << where;
          EXPECT_EQ(read_bits, bits) << where;
          auto back = decode_image({reinterpret_cast<const unsigned char*>(png->data()), png->size()}, "x.png",
                                   Transfer::linear);
          ASSERT_TRUE(back) << back.error().to_string();
          EXPECT_EQ(back->pixels, image.pixels) << where;
          EXPECT_EQ(back->alpha_channel, image.alpha_channel) << where;
        }
      }
    }
  }
}

TEST(Png, ChunksAreFramedAsTheSpecSaysAndLargeStreamsAreSplit) {
  // 1024x1024 RGBA noise: about 4 MB of deflate, so several IDAT chunks of 1 MiB.
  const int w = 1024, h = 1024;
  const Image image = image_of_codes(w, h, 4, test_codes(w, h, 4, 255, 5), 255);
  WriteOptions options;
  options.type = SampleType::u8;
  options.colorspace = "sRGB";
  auto png = encode_image(image, "x.png", options);
  ASSERT_TRUE(png);
  const auto chunks = chunks_of(*png);
  ASSERT_GE(chunks.size(), 4u);
  EXPECT_EQ(chunks.front().type, "IHDR");
  EXPECT_EQ(chunks.front().data, std::string("\0\0\x04\0\0\0\x04\0\x08\x06\0\0\0", 13));  // 8-bit RGBA, no interlace
  EXPECT_EQ(chunks.back().type, "IEND");
  EXPECT_TRUE(chunks.back().data.empty());
  std::vector<std::string> order;
  std::string stream;
  for (const Chunk& c : chunks) {
    order.push_back(c.type);
    if (c.type == "IDAT") {
      EXPECT_LE(c.data.size(), std::size_t{1} << 20);
      stream += c.data;
    }
  }
  EXPECT_GE(std::count(order.begin(), order.end(), "IDAT"), 2);
  // Colour chunks before the first IDAT, IDATs consecutive.
  const auto first_idat = std::find(order.begin(), order.end(), "IDAT") - order.begin();
  const auto last_idat = order.rend() - std::find(order.rbegin(), order.rend(), "IDAT") - 1;
  EXPECT_EQ(last_idat - first_idat + 1, std::count(order.begin(), order.end(), "IDAT"));
  EXPECT_LT(std::find(order.begin(), order.end(), "sRGB") - order.begin(), first_idat);
  // The concatenated IDATs are one zlib stream (zlib's inflate): filter byte + row per row.
  std::vector<unsigned char> raw(std::size_t(h) * (1 + std::size_t(w) * 4) + 1);
  uLongf raw_size = uLongf(raw.size());
  ASSERT_EQ(uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(stream.data()), uLong(stream.size())), Z_OK);
  EXPECT_EQ(raw_size, uLongf(std::size_t(h) * (1 + std::size_t(w) * 4)));
  for (int y = 0; y < h; ++y) EXPECT_LE(raw[std::size_t(y) * (1 + std::size_t(w) * 4)], 4) << "row " << y;
}

TEST(Png, ColourChunksFollowTheColourSpaceTag) {
  const Image image = image_of_codes(2, 2, 3, test_codes(2, 2, 3, 255, 1), 255);
  auto types_for = [&](const std::string& colorspace) {
    WriteOptions options;
    options.type = SampleType::u8;
    options.colorspace = colorspace;
    std::vector<std::string> types;
    for (const Chunk& c : chunks_of(encode_image(image, "x.png", options).value())) {
      if (c.type != "IDAT") types.push_back(c.type + (c.type == "gAMA" ? ":" + std::to_string(be32(c.data, 0)) : ""));
    }
    return types;
  };
  EXPECT_EQ(types_for(""), (std::vector<std::string>{"IHDR", "IEND"}));
  EXPECT_EQ(types_for("sRGB"), (std::vector<std::string>{"IHDR", "gAMA:45455", "sRGB", "cHRM", "tEXt", "IEND"}));
  EXPECT_EQ(types_for("Linear"), (std::vector<std::string>{"IHDR", "gAMA:100000", "tEXt", "IEND"}));
  EXPECT_EQ(types_for("Gamma2.2"), (std::vector<std::string>{"IHDR", "gAMA:45455", "tEXt", "IEND"}));
  // What OIIO reads back as the colour space.
  WriteOptions options;
  options.type = SampleType::u8;
  options.colorspace = "Linear";
  test::TempDir dir;
  auto in = open_in_libpng(encode_image(image, "x.png", options).value(), dir);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().get_string_attribute("oiio:ColorSpace"), "Linear");
}

TEST(Png, LevelsTradeSizeForTimeAndAreNamed) {
  const Image image = image_of_codes(256, 256, 3, test_codes(256, 256, 3, 255, 9), 255);
  std::vector<std::size_t> sizes;
  for (int level : {0, 1, 12}) {
    WriteOptions options;
    options.type = SampleType::u8;
    options.png_level = level;
    sizes.push_back(encode_image(image, "x.png", options).value().size());
  }
  EXPECT_GT(sizes[0], sizes[1]);  // level 0 stores
  EXPECT_GE(sizes[1], sizes[2]);
  EXPECT_GE(sizes[0], std::size_t(256) * (1 + 256 * 3));

  EXPECT_EQ(png_level_from_name("fast"), kPngLevelFast);
  EXPECT_EQ(png_level_from_name("default"), kPngLevelDefault);
  EXPECT_EQ(png_level_from_name("small"), kPngLevelSmallest);
  EXPECT_EQ(png_level_from_name("0"), 0);
  EXPECT_EQ(png_level_from_name("12"), 12);
  for (const char* bad : {"13", "-1", "", "6x", "fastest", " 6"}) EXPECT_FALSE(png_level_from_name(bad)) << bad;

  WriteOptions bad;
  bad.type = SampleType::u8;
  bad.png_level = 13;
  auto refused = encode_image(image, "x.png", bad);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("not 0 to 12"), std::string::npos);
}

TEST(Png, FileWritesMatchMemoryEncodesAndAreAtomic) {
  test::TempDir dir;
  const Image image = image_of_codes(5, 3, 2, test_codes(5, 3, 2, 65535, 4), 65535);
  WriteOptions options;
  options.type = SampleType::u16;
  ASSERT_TRUE(write_image(image, dir / "a.png", options));
  std::ifstream file(dir / "a.png", std::ios::binary);
  const std::string on_disk((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(on_disk, encode_image(image, "x.png", options).value());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
  // A folder that cannot be made (under a file): an error naming the file, nothing written.
  const auto under_file = write_image(image, dir / "a.png" / "b.png", options);
  ASSERT_FALSE(under_file);
  EXPECT_EQ(under_file.error().path, (dir / "a.png" / "b.png").string());
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

}  // namespace
}  // namespace matbake::image
