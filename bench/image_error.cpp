// Error of a converted image against the float64 formula: `image_error SRGB8.png LINEAR.exr`
// decodes every colour sample of the 8-bit sRGB input in float64 and compares it with the output;
// alpha is compared with code / 255. For comparing matbake's and oiiotool's outputs.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "matbake/color.hpp"

namespace {

bool read(const std::string& path, OIIO::TypeDesc type, std::vector<double>& out, OIIO::ImageSpec& spec) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) return false;
  spec = in->spec();
  out.resize(std::size_t(spec.width) * spec.height * spec.nchannels);
  return in->read_image(0, 0, 0, spec.nchannels, type, out.data());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: image_error SRGB8.png LINEAR.exr\n");
    return 2;
  }
  std::vector<double> source, result;
  OIIO::ImageSpec source_spec, result_spec;
  if (!read(argv[1], OIIO::TypeDesc::DOUBLE, source, source_spec) ||
      !read(argv[2], OIIO::TypeDesc::DOUBLE, result, result_spec) || source.size() != result.size()) {
    std::fprintf(stderr, "image_error: cannot read or match %s and %s\n", argv[1], argv[2]);
    return 1;
  }
  double max_colour = 0, sum_sq = 0, max_alpha = 0;
  const int channels = source_spec.nchannels, alpha = source_spec.alpha_channel;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const int c = int(i % channels);
    const double code = std::round(source[i] * 255.0) / 255.0;
    if (c == alpha) {
      max_alpha = std::max(max_alpha, std::abs(result[i] - code));
    } else {
      const double e = std::abs(result[i] - matbake::color::linear_from_encoded(matbake::color::Transfer::srgb, code));
      max_colour = std::max(max_colour, e);
      sum_sq += e * e;
    }
  }
  const double colour_samples = double(source.size()) * (channels - (alpha >= 0)) / channels;
  std::printf("colour max_abs %.3g rms_abs %.3g | alpha max_abs %.3g\n", max_colour, std::sqrt(sum_sq / colour_samples),
              max_alpha);
  return 0;
}
