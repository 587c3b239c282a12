#include "support/render_psnr.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "matbake/image.hpp"

namespace matbake::test {
namespace fs = std::filesystem;

double render_psnr(const fs::path& reference, const fs::path& test) {
  const auto a = image::read_image(reference, color::Transfer::linear);
  const auto b = image::read_image(test, color::Transfer::linear);
  if (!a || !b) throw std::runtime_error("render_psnr: a render could not be read");
  if (a->width != b->width || a->height != b->height || a->channels != b->channels || a->channels < 3) {
    throw std::runtime_error("render_psnr: the renders differ in size or channels");
  }
  const int c = a->channels;
  const auto is_background = [&](const std::vector<float>& p, std::size_t i) {
    for (int k = 0; k < 3; ++k) {
      if (p[i + std::size_t(k)] != a->pixels[std::size_t(k)]) return false;
    }
    return true;
  };
  double squared = 0;
  std::size_t samples = 0;
  for (std::size_t i = 0; i < a->pixels.size(); i += std::size_t(c)) {
    if (is_background(a->pixels, i) && is_background(b->pixels, i)) continue;
    for (int k = 0; k < 3; ++k) {
      const double d = 255.0 * (double(a->pixels[i + std::size_t(k)]) - double(b->pixels[i + std::size_t(k)]));
      squared += d * d;
    }
    samples += 3;
  }
  if (samples == 0 || squared == 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / (squared / double(samples)));
}

}  // namespace matbake::test
