// KTX2 delivery against basisu's own mips: for one texture, matbake's chain (each level from the
// source, linear light, renormalised normals, alpha coverage) encoded level by level, and the same
// source through `basisu -mipmap` at equal codec settings. Both files are transcoded by basisu
// (-unpack, BC7) and every level compared with a float64 reference chain made from the source:
// PSNR per channel (8-bit codes as stored: sRGB for colour), mean / 95th percentile / max angular
// error for normal maps, coverage per level for a MASK texture. Sizes, bits per base texel and encode
// time (2 encoder threads) beside them. Markdown on stdout.
//   bench_delivery WORK_FOLDER CLASS CODEC FILE [ALPHA_CUTOFF]     CLASS colour|data|normal, CODEC etc1s|uastc
// scripts/bench-delivery.sh runs it on the Khronos textures (docs/delivery.md).
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "lib/src/delivery/encode.hpp"
#include "matbake/color.hpp"
#include "matbake/delivery.hpp"
#include "matbake/image.hpp"
#include "matbake/ktx2.hpp"

namespace fs = std::filesystem;
using namespace matbake;
using namespace matbake::delivery;

namespace {

// ---- The float64 reference: the documented Kaiser weights, separable, summed in float64, repeat edges

struct Plane {
  int width = 0, height = 0, channels = 0;
  std::vector<double> v;
  double& at(int x, int y, int c) { return v[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels) + std::size_t(c)]; }
  double at(int x, int y, int c) const { return v[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(channels) + std::size_t(c)]; }
};

// One axis of the reference: out(x) = Σ w(i) in(i) / Σ w(i), w the window at the output's footprint.
Plane shrink_axis(const Plane& in, int size, bool along_x) {
  const int n = along_x ? in.width : in.height;
  Plane out{along_x ? size : in.width, along_x ? in.height : size, in.channels, {}};
  out.v.assign(std::size_t(out.width) * std::size_t(out.height) * std::size_t(out.channels), 0.0);
  const double step = double(n) / size, footprint = std::max(1.0, step);
  for (int o = 0; o < size; ++o) {
    const double centre = (o + 0.5) * step;
    std::vector<std::pair<int, double>> taps;
    double sum = 0;
    for (int i = int(std::floor(centre - 3 * footprint)); i <= int(std::ceil(centre + 3 * footprint)); ++i) {
      const double w = kaiser_weight((i + 0.5 - centre) / footprint);
      if (w == 0) continue;
      taps.emplace_back(((i % n) + n) % n, w);
      sum += w;
    }
    const int across = along_x ? in.height : in.width;
    for (int a = 0; a < across; ++a) {
      for (int c = 0; c < in.channels; ++c) {
        double acc = 0;
        for (const auto& [i, w] : taps) acc += w * (along_x ? in.at(i, a, c) : in.at(a, i, c));
        (along_x ? out.at(o, a, c) : out.at(a, o, c)) = acc / sum;
      }
    }
  }
  return out;
}

Plane reference_level(const Plane& source, Size size, TextureClass cls) {
  Plane level = source;
  if (size.width != source.width) level = shrink_axis(level, size.width, true);
  if (size.height != source.height) level = shrink_axis(level, size.height, false);
  if (cls == TextureClass::normal) {
    for (std::size_t p = 0; p < level.v.size() / std::size_t(level.channels); ++p) {
      double* t = &level.v[p * std::size_t(level.channels)];
      double n[3] = {2 * t[0] - 1, 2 * t[1] - 1, 2 * t[2] - 1};
      const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int c = 0; c < 3; ++c) t[c] = 0.5 * (l > 0 ? n[c] / l : c == 2) + 0.5;
    }
  }
  return level;
}

// ---- Decoding the KTX2 files with basisu -------------------------------------------------------------

std::vector<image::Image> unpacked_levels(const std::string& basisu, const fs::path& ktx2_file, std::size_t count) {
  const fs::path folder = ktx2_file.parent_path() / (ktx2_file.stem().string() + "-unpacked");
  fs::create_directories(folder);
  const std::string command = "cd '" + folder.string() + "' && '" + basisu + "' -unpack -no_ktx -format_only 6 -file '" +
                              fs::absolute(ktx2_file).string() + "' >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) {
    std::fprintf(stderr, "basisu -unpack failed on %s\n", ktx2_file.c_str());
    std::exit(1);
  }
  std::vector<image::Image> levels;
  for (std::size_t l = 0; l < count; ++l) {
    const fs::path png = folder / (ktx2_file.stem().string() + "_unpacked_rgba_BC7_RGBA_" + std::to_string(l) + "_0000.png");
    auto im = image::read_image(png, color::Transfer::linear);  // codes / 255, as stored
    if (!im) {
      std::fprintf(stderr, "%s\n", im.error().to_string().c_str());
      std::exit(1);
    }
    levels.push_back(std::move(*im));
  }
  return levels;
}

// The stored code (0–255, unrounded) the reference's value would be: sRGB-encoded for colour.
double code_of(double value, TextureClass cls, int channel) {
  const double v = std::clamp(value, 0.0, 1.0);
  return 255 * (cls == TextureClass::colour && channel < 3 ? color::encoded_from_linear(color::Transfer::srgb, v) : v);
}

struct ReferenceError {
  double psnr[4] = {0, 0, 0, 0};
  double angle_mean = 0, angle_p95 = 0, angle_max = 0;  // degrees, normal maps
  double coverage = 0;
};

ReferenceError compare(const Plane& ref, const image::Image& decoded, TextureClass cls, int channels, float cutoff) {
  ReferenceError e;
  const std::size_t pixels = std::size_t(ref.width) * std::size_t(ref.height);
  for (int c = 0; c < channels; ++c) {
    double sum = 0;
    for (std::size_t p = 0; p < pixels; ++p) {
      const double d = code_of(ref.v[p * std::size_t(ref.channels) + std::size_t(c)], cls, c) -
                       255.0 * decoded.pixels[p * std::size_t(decoded.channels) + std::size_t(c)];
      sum += d * d;
    }
    e.psnr[c] = std::min(99.0, sum == 0 ? 99 : 10 * std::log10(255.0 * 255.0 / (sum / double(pixels))));  // 99: exact
  }
  if (cls == TextureClass::normal) {
    std::vector<double> angles;
    for (std::size_t p = 0; p < pixels; ++p) {
      double a[3], b[3], la = 0, lb = 0, dot = 0;
      for (int c = 0; c < 3; ++c) {
        a[c] = 2 * ref.v[p * std::size_t(ref.channels) + std::size_t(c)] - 1;
        b[c] = 2 * double(decoded.pixels[p * std::size_t(decoded.channels) + std::size_t(c)]) - 1;
        la += a[c] * a[c], lb += b[c] * b[c];
      }
      for (int c = 0; c < 3; ++c) dot += a[c] * b[c];
      angles.push_back(std::acos(std::clamp(dot / std::sqrt(la * lb + 1e-300), -1.0, 1.0)) * 180 / std::numbers::pi);
    }
    std::sort(angles.begin(), angles.end());
    double sum = 0;
    for (double a : angles) sum += a;
    e.angle_mean = sum / double(angles.size());
    e.angle_p95 = angles[std::min(angles.size() - 1, std::size_t(0.95 * double(angles.size())))];
    e.angle_max = angles.back();
  }
  if (cutoff > 0) e.coverage = alpha_coverage(decoded, cutoff);
  return e;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void write_file(const fs::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: bench_delivery WORK_FOLDER colour|data|normal etc1s|uastc FILE [ALPHA_CUTOFF]\n");
    return 2;
  }
  const fs::path work = argv[1];
  const TextureClass cls = *value_in(kTextureClassNames, argv[2]);
  const Codec codec = *value_in(kCodecNames, argv[3]);
  const fs::path file = argv[4];
  const float cutoff = argc > 5 ? std::stof(argv[5]) : 0.0f;
  fs::create_directories(work);
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  auto encoder = find_encoder();
  if (!encoder) {
    std::fprintf(stderr, "%s\n", encoder.error().to_string().c_str());
    return 1;
  }
  auto source = image::read_image(file, cls == TextureClass::colour ? color::Transfer::srgb : color::Transfer::linear);
  if (!source) {
    std::fprintf(stderr, "%s\n", source.error().to_string().c_str());
    return 1;
  }
  const Size base{source->width, source->height};
  const std::vector<Size> sizes = mip_sizes(base);
  const int channels = source->alpha_channel >= 0 && has_alpha(*source) ? 4 : 3;
  const std::string name = file.stem().string() + "-" + argv[3];

  // matbake: the chain, then UASTC level by level (assembled here), or ETC1S through basisu's mips;
  // with the Kaiser filter, which the float64 reference and basisu's -mipmap both use.
  const ClassOptions options{.codec = codec};
  const Sampling kaiser{.filter = Filter::kaiser};
  EncodeRequest request{.texture_class = cls, .options = options, .sampling = kaiser, .alpha = channels == 4,
                        .scratch = work / (name + ".ktx2"), .threads = 2};
  auto start = std::chrono::steady_clock::now();
  auto encoded = encode_texture(*encoder, *source, base, {cls, kaiser, cutoff > 0 ? std::optional(cutoff) : std::nullopt, cutoff > 0},
                                request, "bench");
  if (!encoded) {
    std::fprintf(stderr, "%s\n", encoded.error().to_string().c_str());
    return 1;
  }
  const std::vector<unsigned char>& ours = encoded->file;
  const double our_seconds = seconds_since(start);
  write_file(work / (name + "-matbake.ktx2"), ours);

  // basisu alone: the source file through its own -mipmap, equal codec settings (zstd 18 for UASTC).
  std::vector<std::string> args = encoder_arguments({.texture_class = cls, .options = options, .mipmaps = false, .alpha = channels == 4});
  std::string command = "'" + encoder->program.string() + "'";
  for (const std::string& a : args) command += " " + (a == "-ktx2_no_zstandard" ? std::string("-ktx2_zstandard_level 18") : a);
  const fs::path theirs_path = work / (name + "-basisu.ktx2");
  command += " -mipmap -max_threads 2 -output_file '" + theirs_path.string() + "' '" + file.string() + "' >/dev/null 2>&1";
  start = std::chrono::steady_clock::now();
  if (std::system(command.c_str()) != 0) {
    std::fprintf(stderr, "basisu failed: %s\n", command.c_str());
    return 1;
  }
  const double their_seconds = seconds_since(start);
  const auto theirs_size = fs::file_size(theirs_path);

  const auto ours_levels = unpacked_levels(encoder->program.string(), work / (name + "-matbake.ktx2"), sizes.size());
  const auto theirs_levels = unpacked_levels(encoder->program.string(), theirs_path, sizes.size());
  Plane src{base.width, base.height, channels, {}};
  for (std::size_t p = 0; p < std::size_t(base.width) * std::size_t(base.height); ++p) {
    for (int c = 0; c < channels; ++c) src.v.push_back(source->pixels[p * std::size_t(source->channels) + std::size_t(c < 3 && source->channels < 3 ? 0 : c)]);
  }
  const double texels = double(base.width) * base.height;
  std::printf("### %s (%s, %s, %dx%d)\n\n", file.filename().c_str(), argv[2], argv[3], base.width, base.height);
  std::printf("| | bytes | bits/texel | encode s (2 threads) |\n|---|---|---|---|\n");
  std::printf("| matbake | %zu | %.2f | %.2f |\n| basisu -mipmap | %llu | %.2f | %.2f |\n\n", ours.size(), 8.0 * double(ours.size()) / texels,
              our_seconds, (unsigned long long)theirs_size, 8.0 * double(theirs_size) / texels, their_seconds);
  if (cutoff > 0) std::printf("source coverage at alpha ≥ %.2f: %.4f\n\n", cutoff, alpha_coverage(*source, cutoff));
  std::printf("| level | size | matbake PSNR R/G/B%s | basisu PSNR R/G/B%s |%s%s\n", channels == 4 ? "/A" : "", channels == 4 ? "/A" : "",
              cls == TextureClass::normal ? " matbake angle mean/p95/max ° | basisu angle mean/p95/max ° |" : "",
              cutoff > 0 ? " matbake coverage | basisu coverage |" : "");
  std::printf("|---|---|---|---|%s%s\n", cls == TextureClass::normal ? "---|---|" : "", cutoff > 0 ? "---|---|" : "");
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    const Plane ref = reference_level(src, sizes[l], cls);
    const ReferenceError a = compare(ref, ours_levels[l], cls, channels, cutoff);
    const ReferenceError b = compare(ref, theirs_levels[l], cls, channels, cutoff);
    const auto psnrs = [&](const ReferenceError& e) {
      std::string s;
      for (int c = 0; c < channels; ++c) {
        char text[16];
        std::snprintf(text, sizeof text, "%s%.1f", c ? "/" : "", e.psnr[c]);
        s += text;
      }
      return s;
    };
    std::printf("| %zu | %dx%d | %s | %s |", l, sizes[l].width, sizes[l].height, psnrs(a).c_str(), psnrs(b).c_str());
    if (cls == TextureClass::normal) {
      std::printf(" %.2f/%.2f/%.1f | %.2f/%.2f/%.1f |", a.angle_mean, a.angle_p95, a.angle_max, b.angle_mean, b.angle_p95, b.angle_max);
    }
    if (cutoff > 0) std::printf(" %.4f | %.4f |", a.coverage, b.coverage);
    std::printf("\n");
  }
  std::printf("\n");
  return 0;
}
