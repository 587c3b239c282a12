// The bake bench's pairs and its error measure (scripts/bench-bake-blender.sh):
//   bake_pairs write DIR
//     writes four high/low pairs with known geometry (each high-poly also as NAME_painted.gltf, with
//     vertex colours): sphere (an icosphere of 5120 smooth triangles
//     onto a flat-shaded one of 320, each low triangle its own UV island), bump (a hemisphere of
//     radius 0.5 on a 128 × 128 grid onto a quad), sculpt (a unit sphere displaced by a product
//     of sines, 20480 triangles, onto a smooth icosphere of 320) and rivets (a 12 × 12 grid of
//     hemispheres of radius 0.03 on a plane onto a quad: detail a few texels wide, with creases,
//     where a texel's footprint is not one normal);
//   bake_pairs error normal|position|colour|scalar LOW.gltf REFERENCE IMAGE...
//     compares each IMAGE with REFERENCE over the texels whose centre a triangle of LOW's UV set 0
//     covers (padding and empty texels left out): normal maps by the angle between decoded
//     directions (mean and 99th percentile, degrees), scalar maps (the first channel) by RMSE and
//     the largest difference, colours (RGB) by the RMS of the channels' differences (RMSE and the
//     largest), every value rounded to 8 bits first (as it is delivered; a float file's colours
//     encoded to sRGB); position maps (float files) by the distance between the positions (mean and
//     99th percentile);
//   bake_pairs psnr REFERENCE.png RENDER.png
//     the PSNR of a render against another over what either shows (the runtime tests' measure).
#include <OpenImageIO/imageio.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "matbake/color.hpp"
#include "matbake/scene.hpp"
#include "tests/support/gltf_builder.hpp"
#include "tests/support/render_psnr.hpp"
#include "tests/support/shapes.hpp"

namespace fs = std::filesystem;
using namespace matbake;

namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

// A pair's high-poly as NAME_high.gltf, and as NAME_painted.gltf with vertex colours (linear RGB in
// [0.1, 0.9], smooth bands a few across the pair) for the colour transfer; the renders compare the
// grey one with the grey low-poly.
void write_high(const fs::path& dir, const std::string& name, const std::vector<glm::dvec3>& positions,
                const std::vector<glm::dvec3>& normals, const Triangles& triangles) {
  test::write_grey_mesh(dir / (name + "_high.gltf"), positions, normals, {}, triangles);
  std::vector<glm::dvec3> colors;
  for (const glm::dvec3& p : positions) {
    colors.push_back(0.5 + 0.4 * glm::dvec3(std::sin(5 * p.x + 1), std::sin(7 * p.y + 2), std::sin(9 * p.z + 3)));
  }
  test::write_grey_mesh(dir / (name + "_painted.gltf"), positions, normals, {}, triangles, colors);
}

void write_sphere(const fs::path& dir) {
  const test::Icosphere fine = test::icosphere(4);
  write_high(dir, "sphere", fine.vertices, fine.vertices, fine.triangles);
  const test::AtlasMesh low = test::icosphere_atlas(2, true);
  test::write_grey_mesh(dir / "sphere_low.gltf", low.positions, low.normals, low.texcoords, low.triangles);
}

// The low-poly of the flat pairs: [-1, 1]² at z = 0, u along x, v against y (glTF's v runs down the
// texture).
void write_quad(const fs::path& file) {
  const std::vector<glm::dvec3> quad = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const std::vector<glm::dvec3> up(4, glm::dvec3(0, 0, 1));
  const std::vector<glm::vec2> uv = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  test::write_grey_mesh(file, quad, up, uv, {{0, 1, 2}, {0, 2, 3}});
}

// z = √(r² − x² − y²) inside radius r, 0 outside; the normal analytic on each part.
void write_bump(const fs::path& dir) {
  constexpr int kCells = 128;
  constexpr double kRadius = 0.5;
  std::vector<glm::dvec3> positions, normals;
  Triangles triangles;
  for (int j = 0; j <= kCells; ++j) {
    for (int i = 0; i <= kCells; ++i) {
      const double x = -1 + 2.0 * i / kCells, y = -1 + 2.0 * j / kCells, rr = x * x + y * y;
      const double z = rr < kRadius * kRadius ? std::sqrt(kRadius * kRadius - rr) : 0;
      positions.push_back({x, y, z});
      normals.push_back(z > 0 ? glm::dvec3(x, y, z) / kRadius : glm::dvec3(0, 0, 1));
    }
  }
  for (std::uint32_t j = 0; j < kCells; ++j) {
    for (std::uint32_t i = 0; i < kCells; ++i) {
      const std::uint32_t a = j * (kCells + 1) + i, b = a + 1, c = a + kCells + 1, d = c + 1;
      triangles.push_back({a, b, d});
      triangles.push_back({a, d, c});
    }
  }
  write_high(dir, "bump", positions, normals, triangles);
  write_quad(dir / "bump_low.gltf");
}

// A sculpt-like surface: r = 1 + 0.06 sin(6x + 1) sin(6y) sin(6z + 2) over an icosphere of 20480
// triangles, normals the area-weighted mean of the faces around each vertex (as a modeller's).
void write_sculpt(const fs::path& dir) {
  test::Icosphere sphere = test::icosphere(5);
  for (glm::dvec3& v : sphere.vertices) v *= 1 + 0.06 * std::sin(6 * v.x + 1) * std::sin(6 * v.y) * std::sin(6 * v.z + 2);
  std::vector<glm::dvec3> normals(sphere.vertices.size(), glm::dvec3(0));
  for (const auto& t : sphere.triangles) {
    const glm::dvec3 area = glm::cross(sphere.vertices[t[1]] - sphere.vertices[t[0]], sphere.vertices[t[2]] - sphere.vertices[t[0]]);
    for (const std::uint32_t v : t) normals[v] += area;
  }
  for (glm::dvec3& n : normals) n = glm::normalize(n);
  write_high(dir, "sculpt", sphere.vertices, normals, sphere.triangles);
  const test::AtlasMesh low = test::icosphere_atlas(2, false);
  test::write_grey_mesh(dir / "sculpt_low.gltf", low.positions, low.normals, low.texcoords, low.triangles);
}

// Rivets: a hemisphere of radius 0.03 (12 segments around, 4 rings, radial normals) at each cell of
// a 12 × 12 grid over the plane z = 0 of [-1, 1]², which is two triangles of its own.
void write_rivets(const fs::path& dir) {
  constexpr int kGrid = 12, kAround = 12, kRings = 4;
  constexpr double kRadius = 0.03;
  std::vector<glm::dvec3> positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  std::vector<glm::dvec3> normals(4, glm::dvec3(0, 0, 1));
  Triangles triangles = {{0, 1, 2}, {0, 2, 3}};
  for (int gy = 0; gy < kGrid; ++gy) {
    for (int gx = 0; gx < kGrid; ++gx) {
      const glm::dvec3 centre(-1 + (gx + 0.5) * 2.0 / kGrid, -1 + (gy + 0.5) * 2.0 / kGrid, 0);
      const auto pole = std::uint32_t(positions.size());
      positions.push_back(centre + glm::dvec3(0, 0, kRadius));
      normals.push_back({0, 0, 1});
      for (int ring = 1; ring <= kRings; ++ring) {
        const double polar = M_PI / 2 * ring / kRings;
        for (int s = 0; s < kAround; ++s) {
          const double azimuth = 2 * M_PI * s / kAround;
          const glm::dvec3 n(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar));
          positions.push_back(centre + kRadius * n);
          normals.push_back(n);
        }
      }
      const auto at = [&](int ring, int s) { return ring == 0 ? pole : pole + 1 + std::uint32_t((ring - 1) * kAround + s % kAround); };
      for (int s = 0; s < kAround; ++s) {
        triangles.push_back({at(0, 0), at(1, s), at(1, s + 1)});
        for (int ring = 1; ring < kRings; ++ring) {
          triangles.push_back({at(ring, s), at(ring + 1, s), at(ring + 1, s + 1)});
          triangles.push_back({at(ring, s), at(ring + 1, s + 1), at(ring, s + 1)});
        }
      }
    }
  }
  write_high(dir, "rivets", positions, normals, triangles);
  write_quad(dir / "rivets_low.gltf");
}

// Texels (row-major) whose centre lies in a triangle of UV set 0 of any primitive of `low`.
std::vector<bool> covered_texels(const fs::path& low, int width, int height) {
  std::vector<bool> mask(std::size_t(width) * std::size_t(height), false);
  const auto scene = scene::load_scene(low, {.texcoords = true});
  if (!scene) return mask;
  for (const scene::Instance& inst : scene->instances) {
    if (inst.texcoords.empty() || inst.texcoords[0].empty()) continue;
    for (const auto& t : inst.triangles) {
      const glm::dvec2 a(inst.texcoords[0][t[0]]), b(inst.texcoords[0][t[1]]), c(inst.texcoords[0][t[2]]);
      const double area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
      if (area == 0) continue;
      const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}) * width))), x1 = std::min(width - 1, int(std::max({a.x, b.x, c.x}) * width));
      const int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}) * height))), y1 = std::min(height - 1, int(std::max({a.y, b.y, c.y}) * height));
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const glm::dvec2 p((x + 0.5) / width, (y + 0.5) / height);
          const double w0 = ((b.x - p.x) * (c.y - p.y) - (c.x - p.x) * (b.y - p.y)) / area;
          const double w1 = ((c.x - p.x) * (a.y - p.y) - (a.x - p.x) * (c.y - p.y)) / area;
          if (w0 >= 0 && w1 >= 0 && w0 + w1 <= 1) mask[std::size_t(y) * width + x] = true;
        }
      }
    }
  }
  return mask;
}

struct Pixels {
  int width = 0, height = 0, channels = 0;
  std::vector<float> values;  // rounded to 8 bits unless read as floats
  const float* at(std::size_t texel) const { return &values[texel * std::size_t(channels)]; }
};

// How `error` reads an image's samples: as floats; clamped to [0, 1] and rounded to 8 bits, as a
// PNG would hold them; or as sRGB colour in 8 bits (a float file's linear values encoded first, an
// 8-bit file's codes as they are).
enum class Reading { floats, eight_bits, srgb_eight_bits };

bool read_pixels(const std::string& path, Pixels& out, Reading reading) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return false;
  const OIIO::ImageSpec& spec = in->spec();
  out.width = spec.width, out.height = spec.height, out.channels = spec.nchannels;
  out.values.resize(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, out.values.data())) return false;
  if (reading == Reading::floats) return true;
  const bool encode = reading == Reading::srgb_eight_bits && spec.format.is_floating_point();
  for (float& v : out.values) {
    const float stored = encode ? float(color::encoded_from_linear(color::Transfer::srgb, std::clamp(double(v), 0.0, 1.0))) : v;
    v = std::round(std::clamp(stored, 0.0f, 1.0f) * 255.0f) / 255.0f;
  }
  return true;
}

glm::dvec3 decoded_normal(const float* rgb) {
  return glm::normalize(glm::dvec3(2.0 * rgb[0] - 1, 2.0 * rgb[1] - 1, 2.0 * rgb[2] - 1));
}

// What `error` compares: normal maps by angle (°), positions by distance (scene units, as floats),
// colours by the RMS of their channels' differences (sRGB, 8 bits), scalars by difference (8 bits).
enum class ErrorKind { normal, position, colour, scalar };

double texel_error(ErrorKind kind, const float* image, const float* reference) {
  switch (kind) {
    case ErrorKind::normal: {
      const double c = glm::dot(decoded_normal(image), decoded_normal(reference));
      return std::acos(std::clamp(c, -1.0, 1.0)) * 180 / M_PI;
    }
    case ErrorKind::position:
      return glm::distance(glm::dvec3(image[0], image[1], image[2]), glm::dvec3(reference[0], reference[1], reference[2]));
    case ErrorKind::colour:
      return glm::distance(glm::dvec3(image[0], image[1], image[2]), glm::dvec3(reference[0], reference[1], reference[2])) / std::sqrt(3.0);
    case ErrorKind::scalar:
      break;
  }
  return double(image[0]) - double(reference[0]);
}

int compare(ErrorKind kind, const fs::path& low, const std::string& reference_path, const std::vector<std::string>& images) {
  const Reading reading = kind == ErrorKind::position ? Reading::floats
                          : kind == ErrorKind::colour ? Reading::srgb_eight_bits
                                                      : Reading::eight_bits;
  const int channels = kind == ErrorKind::scalar ? 1 : 3;
  Pixels reference;
  if (!read_pixels(reference_path, reference, reading) || reference.channels < channels) {
    std::fprintf(stderr, "bake_pairs: cannot read %s\n", reference_path.c_str());
    return 1;
  }
  const std::vector<bool> mask = covered_texels(low, reference.width, reference.height);
  for (const std::string& path : images) {
    Pixels image;
    if (!read_pixels(path, image, reading) || image.width != reference.width || image.height != reference.height ||
        image.channels < channels) {
      std::fprintf(stderr, "bake_pairs: cannot read %s as a %d×%d image like the reference\n", path.c_str(), reference.width, reference.height);
      return 1;
    }
    std::vector<double> errors;
    for (std::size_t t = 0; t < mask.size(); ++t) {
      if (mask[t]) errors.push_back(texel_error(kind, image.at(t), reference.at(t)));
    }
    double sum = 0, sum_sq = 0, largest = 0;
    for (const double e : errors) sum += e, sum_sq += e * e, largest = std::max(largest, std::abs(e));
    const double n = double(std::max<std::size_t>(errors.size(), 1));
    if (kind == ErrorKind::scalar || kind == ErrorKind::colour) {
      std::printf("%s texels=%zu rmse=%.4f max=%.4f\n", path.c_str(), errors.size(), std::sqrt(sum_sq / n), largest);
      continue;
    }
    std::sort(errors.begin(), errors.end());
    const double p99 = errors.empty() ? 0 : errors[std::size_t(0.99 * double(errors.size() - 1))];
    if (kind == ErrorKind::normal) {
      std::printf("%s texels=%zu mean_deg=%.3f p99_deg=%.3f\n", path.c_str(), errors.size(), sum / n, p99);
    } else {
      std::printf("%s texels=%zu mean=%.2e p99=%.2e\n", path.c_str(), errors.size(), sum / n, p99);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 2 && args[0] == "write") {
    fs::create_directories(args[1]);
    write_sphere(args[1]);
    write_bump(args[1]);
    write_sculpt(args[1]);
    write_rivets(args[1]);
    return 0;
  }
  if (args.size() >= 5 && args[0] == "error") {
    const std::map<std::string, ErrorKind> kinds{
        {"normal", ErrorKind::normal}, {"position", ErrorKind::position}, {"colour", ErrorKind::colour}, {"scalar", ErrorKind::scalar}};
    if (const auto kind = kinds.find(args[1]); kind != kinds.end()) return compare(kind->second, args[2], args[3], {args.begin() + 4, args.end()});
  }
  if (args.size() == 3 && args[0] == "psnr") {
    try {
      std::printf("%.2f\n", test::render_psnr(args[1], args[2]));
      return 0;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bake_pairs: %s\n", e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "usage: bake_pairs write DIR | bake_pairs error normal|scalar LOW.gltf REFERENCE IMAGE... | "
                       "bake_pairs psnr REFERENCE.png RENDER.png\n");
  return 2;
}
