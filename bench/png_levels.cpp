// Size and time of matbake's PNG writer (libdeflate) at each level against OIIO's (libpng + zlib
// at its default level 6, what matbake wrote before), on the PNG files given. One core, the best of
// 3 runs per setting; every file written is decoded back and compared code for code.
//   png_levels FILE.png...
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "matbake/image.hpp"

namespace {

using namespace matbake;

template <class F>
double best_seconds(F&& run) {
  double best = 1e30;
  for (int i = 0; i < 3; ++i) {
    const auto start = std::chrono::steady_clock::now();
    run();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

std::size_t oiio_png_size(const image::Image& img, image::SampleType type) {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create("x.png");
  out->set_ioproxy(&proxy);
  OIIO::ImageSpec spec(img.width, img.height, img.channels, type == image::SampleType::u8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  spec.alpha_channel = img.alpha_channel;
  spec.attribute("oiio:UnassociatedAlpha", 1);
  out->open("x.png", spec);
  out->write_image(OIIO::TypeDesc::FLOAT, img.pixels.data());
  out->close();
  return bytes.size();
}

}  // namespace

int main(int argc, char** argv) {
  std::printf("%-28s %-9s %-5s %9s %8s %10s\n", "file", "writer", "level", "MB/s", "seconds", "size vs libpng");
  for (int a = 1; a < argc; ++a) {
    image::ReadInfo info;
    auto img = image::read_image(argv[a], color::Transfer::linear, &info);
    if (!img) {
      std::fprintf(stderr, "%s: %s\n", argv[a], img.error().message.c_str());
      return 1;
    }
    const image::SampleType type = info.stored_type == image::SampleType::u16 ? image::SampleType::u16 : image::SampleType::u8;
    const double raw_mb = double(img->sample_count()) * (type == image::SampleType::u8 ? 1 : 2) / 1e6;
    std::size_t reference = 0;
    const double oiio_s = best_seconds([&] { reference = oiio_png_size(*img, type); });
    std::string name = OIIO::Filesystem::filename(argv[a]);
    if (name.size() > 28) name = name.substr(name.size() - 28);
    std::printf("%-28s %-9s %-5s %9.1f %8.3f %10zu B\n", name.c_str(), "libpng", "6", raw_mb / oiio_s, oiio_s, reference);
    for (int level : {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 12}) {
      image::WriteOptions options;
      options.type = type;
      options.png_level = level;
      std::string bytes;
      const double s = best_seconds([&] { bytes = image::encode_image(*img, "x.png", options).value(); });
      auto back = image::decode_image({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}, "x.png",
                                      color::Transfer::linear);
      if (!back || back->pixels != img->pixels) {
        std::fprintf(stderr, "%s: level %d does not read back exactly\n", argv[a], level);
        return 1;
      }
      std::printf("%-28s %-9s %-5d %9.1f %8.3f %+9.1f%%\n", name.c_str(), "matbake", level, raw_mb / s, s,
                  100.0 * (double(bytes.size()) / double(reference) - 1));
    }
  }
  return 0;
}
