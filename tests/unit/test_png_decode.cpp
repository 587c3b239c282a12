// matbake's PNG reader (libspng, lib/src/image/png_decode.cpp) against libpng through OIIO, the
// reader it replaced: every PNG in ../shared/testdata (PngSuite's colour types, bit depths and
// interlacing, libpng's tagged images and crashers, the Khronos sample models' textures) decodes to
// the same layout and the same codes; damaged and hostile files are one-line errors.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "matbake/image.hpp"
#include "support/files.hpp"
#include "support/png_chunks.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::image {
namespace {

namespace fs = std::filesystem;
using color::Transfer;
using test::be32, test::deflated, test::kPngSignature, test::png_chunk, test::png_ihdr;

const fs::path kTestdata = MATBAKE_TESTDATA_DIR;

std::vector<fs::path> pngs_under(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (e.is_regular_file() && ext == ".png") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// One line naming the file.
void expect_one_line_error(const Status& s, const std::string& name) {
  ASSERT_FALSE(s) << name;
  EXPECT_EQ(s.error().path, name);
  EXPECT_FALSE(s.error().message.empty());
  EXPECT_EQ(s.error().message.find('\n'), std::string::npos) << s.error().message;
}

template <class T>
Status status_of(const Result<T>& r) {
  if (r) return success();
  return r.error();
}

// Our read (linear: code / max exactly, rounded to float) against the codes libpng gives OIIO.
void expect_same_as_libpng(const fs::path& png) {
  SCOPED_TRACE(png.string());
  const test::RawImage oiio = test::read_raw(png);
  ASSERT_GT(oiio.width, 0) << "OIIO cannot read it";
  ReadInfo info;
  auto ours = read_image(png, Transfer::linear, &info);
  ASSERT_TRUE(ours) << ours.error().to_string();
  EXPECT_EQ(info.format_name, "png");
  EXPECT_EQ(ours->width, oiio.width);
  EXPECT_EQ(ours->height, oiio.height);
  ASSERT_EQ(ours->channels, oiio.channels);
  EXPECT_EQ(ours->channel_names, oiio.channel_names);
  EXPECT_EQ(ours->alpha_channel, oiio.channels == 2 || oiio.channels == 4 ? oiio.channels - 1 : -1);
  ASSERT_TRUE(oiio.format == "uint8" || oiio.format == "uint16") << oiio.format;
  EXPECT_EQ(info.stored_type, oiio.format == "uint8" ? SampleType::u8 : SampleType::u16);
  const double max_code = oiio.format == "uint8" ? 255.0 : 65535.0;
  ASSERT_EQ(ours->pixels.size(), oiio.samples.size());
  std::size_t different = 0;
  for (std::size_t i = 0; i < oiio.samples.size(); ++i) different += ours->pixels[i] != float(oiio.samples[i] / max_code);
  EXPECT_EQ(different, 0u);
  // The same bytes from memory decode the same, whatever the name.
  const std::string bytes = test::read_bytes(png);
  auto from_memory = decode_image({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}, "texture.bin",
                                  Transfer::linear);
  ASSERT_TRUE(from_memory) << from_memory.error().to_string();
  EXPECT_EQ(from_memory->pixels, ours->pixels);
}

TEST(PngDecode, EveryTestdataPngDecodesToLibpngsCodes) {
  std::vector<fs::path> files = pngs_under(kTestdata / "images/pngsuite");
  for (const fs::path& f : pngs_under(kTestdata / "images/libpng-testpngs")) {
    if (f.parent_path().filename() != "crashers") files.push_back(f);
  }
  const std::size_t images = files.size();
  for (const fs::path& f : pngs_under(kTestdata / "gltf")) {
    if (fs::file_size(f) < (std::size_t{1} << 20)) files.push_back(f);  // the small ones: the large add time, not cases
  }
  if (images == 0) GTEST_SKIP() << "no " << (kTestdata / "images").string();
  EXPECT_GE(images, 80u);
  for (const fs::path& f : files) expect_same_as_libpng(f);
}

// libpng's crashers: libpng refuses bad_iCCP (IHDR CRC) and the huge ancillary chunks that run past
// the end; it drops badcrc's damaged ancillary chunk and reads the pixels. Ours does the same.
TEST(PngDecode, LibpngCrashersAreReadOrRefusedAsLibpngDoes) {
  const fs::path folder = kTestdata / "images/libpng-testpngs/crashers";
  if (!fs::is_directory(folder)) GTEST_SKIP() << "no " << folder.string();
  int refused = 0;
  for (const fs::path& f : pngs_under(folder)) {
    auto ours = read_image(f, Transfer::srgb);
    bool libpng_reads = true;
    try {
      test::read_raw(f);
    } catch (const std::runtime_error&) {
      libpng_reads = false;
    }
    if (libpng_reads) {
      EXPECT_TRUE(ours) << ours.error().to_string();
    } else {
      expect_one_line_error(status_of(ours), f.string());
      ++refused;
    }
  }
  EXPECT_GE(refused, 4);
}

// A valid 3×2 RGB PNG written by hand, so each damage below is exact.
std::string rgb_rows() {  // filter byte 0, then 3 RGB pixels; two rows
  std::string raw;
  for (int y = 0; y < 2; ++y) {
    raw += '\0';
    for (int i = 0; i < 9; ++i) raw += char(10 * y + i);
  }
  return raw;
}
std::string valid_png() {
  return kPngSignature + png_ihdr(3, 2, 8, 2) + png_chunk("IDAT", deflated(rgb_rows())) + png_chunk("IEND", "");
}

TEST(PngDecode, HandWrittenPngDecodesAndEveryTruncationIsAnError) {
  test::TempDir dir;
  const std::string good = valid_png();
  test::write_bytes(dir / "good.png", good);
  auto image = read_image(dir / "good.png", Transfer::linear);
  ASSERT_TRUE(image) << image.error().to_string();
  ASSERT_EQ(image->pixels.size(), 18u);
  const std::string raw = rgb_rows();
  for (int y = 0, i = 0; y < 2; ++y) {
    for (int s = 0; s < 9; ++s, ++i) {
      EXPECT_EQ(image->pixels[std::size_t(i)], float(std::uint8_t(raw[std::size_t(y * 10 + 1 + s)]) / 255.0));
    }
  }
  // Cut anywhere: an error (the header, the rows or the chunks after them are incomplete). The one
  // exception is a cut inside IEND's CRC: IEND (no data) is whole, and libspng does not read on.
  for (std::size_t cut = 0; cut < good.size() - 4; ++cut) {
    const fs::path f = dir / "cut.png";
    test::write_bytes(f, good.substr(0, cut));
    SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(good.size()));
    expect_one_line_error(status_of(read_image(f, Transfer::srgb)), f.string());
  }
}

TEST(PngDecode, DamagedAndHostileHeadersAreOneLineErrors) {
  test::TempDir dir;
  const std::string idat = png_chunk("IDAT", deflated(rgb_rows())), iend = png_chunk("IEND", "");
  std::string bad_crc = valid_png();
  bad_crc[8 + 8 + 4] ^= 1;  // a bit of IHDR's width: its CRC no longer matches
  std::string bad_data = valid_png();
  bad_data[8 + 25 + 8 + 3] ^= 0x55;  // inside the deflate stream
  std::string bad_filter_raw = rgb_rows();
  bad_filter_raw[0] = 9;  // filter types are 0 to 4
  std::string bad_idat_crc = valid_png();
  bad_idat_crc[8 + 25 + idat.size() - 4] ^= 1;  // IDAT's CRC (PngSuite's xcsn0g01)
  std::string signature_byte = valid_png(), lf_mangled = valid_png(), cr_mangled = valid_png();
  signature_byte[1] = 'Q';     // not a PNG signature: goes to OIIO, which refuses it (xs1n0g01)
  lf_mangled.erase(4, 1);      // the signature's "\r\n" -> "\n": a text-mode copy to Unix
  cr_mangled.insert(7, "\r");  // its last "\n" -> "\r\n": a text-mode copy to DOS (xcrn0g04)
  // PngSuite's corrupt x*.png files (not in ../shared/testdata) made again by hand, with the
  // other damages of libpng's crashers and fuzzers.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"signature-byte", signature_byte},
      {"signature-lf", lf_mangled},
      {"signature-cr", cr_mangled},
      {"colour-type-1", kPngSignature + png_ihdr(3, 2, 8, 1) + idat + iend},
      {"colour-type-9", kPngSignature + png_ihdr(3, 2, 8, 9) + idat + iend},
      {"depth-0", kPngSignature + png_ihdr(3, 2, 0, 2) + idat + iend},
      {"depth-3", kPngSignature + png_ihdr(3, 2, 3, 2) + idat + iend},
      {"depth-99", kPngSignature + png_ihdr(3, 2, 99, 2) + idat + iend},
      {"bad-idat-crc", bad_idat_crc},
      {"bad-ihdr-crc", bad_crc},
      {"huge-size", kPngSignature + png_ihdr(100000, 100000, 8, 2) + idat + iend},
      {"zero-width", kPngSignature + png_ihdr(0, 2, 8, 2) + idat + iend},
      {"bad-depth", kPngSignature + png_ihdr(3, 2, 7, 2) + idat + iend},
      {"bad-colour-type", kPngSignature + png_ihdr(3, 2, 8, 5) + idat + iend},
      {"palette-without-plte", kPngSignature + png_ihdr(3, 2, 8, 3) + idat + iend},
      {"no-idat", kPngSignature + png_ihdr(3, 2, 8, 2) + iend},
      {"damaged-deflate", bad_data},
      {"bad-filter", kPngSignature + png_ihdr(3, 2, 8, 2) + png_chunk("IDAT", deflated(bad_filter_raw)) + iend},
      {"rows-missing", kPngSignature + png_ihdr(3, 200, 8, 2) + idat + iend},
      {"huge-text-chunk", kPngSignature + png_ihdr(3, 2, 8, 2) + be32(0x7ffffff0u) + "tEXt" + std::string(64, 'a')},
      {"signature-only", kPngSignature},
  };
  for (const auto& [name, bytes] : cases) {
    SCOPED_TRACE(name);
    const fs::path f = dir / (name + ".png");
    test::write_bytes(f, bytes);
    expect_one_line_error(status_of(read_image(f, Transfer::srgb)), f.string());
    expect_one_line_error(
        status_of(decode_image({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}, name, Transfer::srgb)),
        name);
    // Checked without keeping the pixels (a glTF's images before export): the same refusal.
    expect_one_line_error(status_of(check_image_bytes({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}, name)), name);
    // The command: exit 1, one line, nothing written.
    const auto r = test::matbake({"convert", f.string(), "-o", (dir / "out.exr").string()});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(f.string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
  }
}

// PNG in, PNG or EXR (half/float zip) out never loads OpenImageIO (its ~260 libraries are most of
// a run's start); a format of OIIO's loads it, from beside libmatbake.
TEST(PngDecode, PngToPngOrExrNeverLoadsOpenImageIo) {
  test::TempDir dir;
  test::write_bytes(dir / "in.png", valid_png());
  // The dynamic loader's log of every object it loads, into files of its own (the CLI points
  // stderr elsewhere while it works).
  const auto loaded_oiio = [&](const std::vector<std::string>& args) {
    const fs::path logs = dir / "ld";
    fs::remove_all(logs);
    fs::create_directory(logs);
    const auto r = test::matbake(args, {"LD_DEBUG=files", "LD_DEBUG_OUTPUT=" + (logs / "log").string()});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::string log;
    for (const auto& e : fs::directory_iterator(logs)) log += test::read_bytes(e.path());
    EXPECT_NE(log.find("libmatbake.so"), std::string::npos);  // the log is there
    return log.find("libOpenImageIO.so") != std::string::npos;
  };
  EXPECT_FALSE(loaded_oiio({"convert", (dir / "in.png").string(), "-o", (dir / "out.exr").string()}));
  EXPECT_FALSE(loaded_oiio({"convert", (dir / "in.png").string(), "-o", (dir / "out.png").string(), "--bits", "8"}));
  EXPECT_TRUE(loaded_oiio({"convert", (dir / "in.png").string(), "-o", (dir / "out.tif").string()}));
  EXPECT_TRUE(loaded_oiio({"convert", (dir / "out.tif").string(), "-o", (dir / "back.exr").string()}));
}

}  // namespace
}  // namespace matbake::image
