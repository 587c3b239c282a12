#include "matbake/read_file.hpp"
#include "matbake/preview.hpp"
#include "matbake/workflow.hpp"

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "matbake/shading_catalog.hpp"
#include "matbake/workflow_maps.hpp"
#include "../io/bounded_json.hpp"

namespace matbake::preview {
namespace {

using shading::Vec3;

const Vec3 kView(0, 1, 0);
constexpr double kBallRadius = 0.9;  // of the half cell

std::string describe(const Vec3& c) {
  std::ostringstream s;
  s << c.x << "," << c.y << "," << c.z;
  return s.str();
}

// Outgoing radiance of one channel at normal n, in Schüler's units (the 1/π folded into E).
double shade(const shading::ModelInfo& model, const Vec3& n, double kd, double ks, double gloss,
             const shading::HemisphereLight& sky) {
  double radiance = shading::hemisphere_diffuse(n, kd, sky) + shading::hemisphere_specular(n, kView, ks, gloss, sky);
  const shading::MaterialSample sample{kd, ks, gloss};
  for (const DirectionalLight& light : lights()) {
    const shading::Geometry g = shading::make_geometry(n, light.direction, kView);
    if (g.n_dot_l <= 0) continue;
    double f = model.brdf(g, sample);
    if (model.lobe == shading::Lobe::specular) f += shading::lambert_brdf(kd);
    radiance += std::numbers::pi * f * g.n_dot_l * light.irradiance;
  }
  return radiance;
}

// Channel c of `im` at (u, v) ∈ [0, 1]², bilinear between texel centres; u wraps, v clamps.
double bilinear(const image::Image& im, double u, double v, int c) {
  const double x = u * im.width - 0.5, y = std::clamp(v * im.height - 0.5, 0.0, double(im.height - 1));
  const double fx = std::floor(x), fy = std::floor(y);
  const double tx = x - fx, ty = y - fy;
  const auto at = [&](double px, double py) {
    const int ix = int(((long long)(px) % im.width + im.width) % im.width);
    const int iy = std::min(int(py), im.height - 1);
    return double(im.pixels[(std::size_t(iy) * std::size_t(im.width) + std::size_t(ix)) * std::size_t(im.channels) + std::size_t(c)]);
  };
  return (1 - ty) * ((1 - tx) * at(fx, fy) + tx * at(fx + 1, fy)) + ty * ((1 - tx) * at(fx, fy + 1) + tx * at(fx + 1, fy + 1));
}

// The material's values at normal n: its textures at the ball's UV where it has them.
struct Surface {
  Vec3 kd, ks;
  double gloss, mask;
};
Surface surface_at(const Material& m, const Vec3& n, bool gloss_from_map) {
  Surface s{m.kd, m.ks, m.gloss, 1.0};
  if (!m.textures) return s;
  const double u = 0.5 + std::atan2(n.x, n.y) / (2 * std::numbers::pi);
  const double v = std::acos(std::clamp(n.z, -1.0, 1.0)) / std::numbers::pi;
  const material::Maps& t = *m.textures;
  if (const image::Image* kd = t.find(material::kKd)) s.kd = Vec3(bilinear(*kd, u, v, 0), bilinear(*kd, u, v, 1), bilinear(*kd, u, v, 2));
  if (const image::Image* ks = t.find(material::kKs)) s.ks = Vec3(bilinear(*ks, u, v, 0), bilinear(*ks, u, v, 1), bilinear(*ks, u, v, 2));
  if (const image::Image* g = t.find(material::kGloss); g && gloss_from_map) s.gloss = bilinear(*g, u, v, 0);
  if (const image::Image* mask = t.find(material::kMask)) s.mask = std::clamp(bilinear(*mask, u, v, 0), 0.0, 1.0);
  return s;
}

// The mean of a map's first `channels` channels.
Vec3 mean_of(const image::Image& im) {
  Vec3 sum(0.0);
  const std::size_t texels = std::size_t(im.width) * std::size_t(im.height);
  for (std::size_t p = 0; p < texels; ++p) {
    for (int c = 0; c < 3; ++c) sum[c] += im.pixels[p * std::size_t(im.channels) + std::size_t(std::min(c, im.channels - 1))];
  }
  return sum / double(texels);
}

// A 1×1 map of `value` at the size of `maps`, where `maps` has no map `name`.
void fill_constant(material::Maps& maps, const char* name, float value) {
  if (maps.find(name)) return;
  image::Image im;
  im.width = maps.width, im.height = maps.height, im.channels = 1;
  im.pixels.assign(im.sample_count(), value);
  maps.maps[name] = std::move(im);
}

}  // namespace

Result<Material> material_from_maps(std::string name, const material::Maps& given) {
  return guarded("", [&]() -> Result<Material> {
    material::Maps maps = given;
    const bool metal_rough = maps.metal_rough();
    if (metal_rough && maps.spec_gloss()) {
      return Error{"", "give Schüler maps (kd, ks, gloss) or metal-rough ones (base_color, metallic, roughness), not both", true};
    }
    if (metal_rough) {
      if (!maps.find(material::kBaseColor)) return Error{"", "metal-rough maps need base_color", true};
      fill_constant(maps, "metallic", 0.0f);
      fill_constant(maps, "roughness", 0.5f);
      workflow::ConversionReport report;
      auto converted = workflow::spec_gloss_from_metal_rough(maps, workflow::RoughnessMapping::walter, report);
      if (!converted) return converted.error();
      maps = std::move(*converted);
    }
    Material m;
    m.name = std::move(name);
    auto textures = std::make_shared<material::Maps>();
    textures->width = maps.width, textures->height = maps.height;
    for (const char* key : {"kd", "ks", "gloss", "mask"}) {
      const image::Image* map = maps.find(key);
      if (!map) continue;
      const Vec3 mean = mean_of(*map);
      if (std::string_view(key) == "kd") m.kd = mean;
      if (std::string_view(key) == "ks") m.ks = mean;
      if (std::string_view(key) == "gloss") m.gloss = mean.x;
      if (map->width * map->height > 1 || std::string_view(key) == "mask") textures->maps[key] = *map;
    }
    if (!textures->maps.empty()) m.textures = std::move(textures);
    if (Status s = check(m); !s) return s.error();
    return m;
  });
}

const std::vector<DirectionalLight>& lights() {
  static const std::vector<DirectionalLight> rig = {
      {glm::normalize(Vec3(-0.55, 0.6, 0.6)), 1.6},  // key: upper left, in front
      {glm::normalize(Vec3(0.8, -0.2, 0.35)), 0.6},   // rim: right, slightly behind
  };
  return rig;
}

Material from_metal_rough(std::string name, Vec3 base_color, double metallic, double roughness) {
  const workflow::SpecGloss sg =
      workflow::spec_gloss_from_metal_rough({base_color, metallic, roughness}, workflow::RoughnessMapping::walter);
  return {std::move(name), sg.kd, sg.ks, sg.gloss, nullptr};
}

Status check(const Material& m) {
  const auto bad_colour = [](const Vec3& c) {
    for (int i = 0; i < 3; ++i) {
      if (!(c[i] >= 0.0 && c[i] <= 1.0)) return true;  // also NaN
    }
    return false;
  };
  const std::string who = "material '" + m.name + "': ";
  if (bad_colour(m.kd)) return Error{"", who + "kd " + describe(m.kd) + " is outside [0, 1]", true};
  if (bad_colour(m.ks)) return Error{"", who + "ks " + describe(m.ks) + " is outside [0, 1]", true};
  if (!(m.gloss >= 0.0 && m.gloss <= 1.0)) {
    return Error{"", who + "gloss " + std::to_string(m.gloss) + " is outside [0, 1]", true};
  }
  return success();
}

constexpr std::size_t kMaterialFileLimit = 16u << 20;  // a list of colours and numbers

Result<std::vector<Material>> load_materials(const std::filesystem::path& path) {
  return guarded(path.string(), [&]() -> Result<std::vector<Material>> {
    std::string text;
    if (!read_whole_file(path, text)) return Error{path.string(), "cannot open (missing, unreadable or not a file)"};
    std::vector<Material> materials;
    if (std::string problem = json_limit_problem(text, kMaterialFileLimit); !problem.empty()) return Error{path.string(), problem};
    try {
      const nlohmann::json doc = nlohmann::json::parse(text);
      if (!doc.is_array()) return Error{path.string(), "expected a JSON array of materials"};
      for (const auto& entry : doc) {
        const auto colour = [&](const char* key) {
          const auto& c = entry.at(key);
          return Vec3(c.at(0).get<double>(), c.at(1).get<double>(), c.at(2).get<double>());
        };
        const std::string name = entry.value("name", "material " + std::to_string(materials.size() + 1));
        Material m;
        if (entry.contains("base_color")) {
          m = from_metal_rough(name, colour("base_color"), entry.value("metallic", 0.0), entry.value("roughness", 0.5));
        } else {
          m.name = name;
          m.kd = colour("kd");
          m.ks = colour("ks");
          m.gloss = entry.at("gloss").get<double>();
        }
        if (Status s = check(m); !s) return Error{path.string(), s.error().message};
        materials.push_back(std::move(m));
      }
    } catch (const nlohmann::json::exception& e) {
      const std::string what = e.what();
      return Error{path.string(), "invalid material JSON: " + what.substr(0, what.find('\n'))};
    }
    if (materials.empty()) return Error{path.string(), "no materials"};
    return materials;
  });
}

Result<Preview> render(const std::vector<Material>& materials, const Options& options) {
  return guarded("", [&]() -> Result<Preview> {
    const shading::ModelInfo* model = shading::find_model(options.model);
    if (model == nullptr) return Error{"", "unknown model '" + options.model + "'", true};
    if (materials.empty()) return Error{"", "no materials to preview", true};
    if (options.cell_size < 8 || options.cell_size > 4096) return Error{"", "cell size must be 8 to 4096", true};
    for (const Material& m : materials) {
      if (Status s = check(m); !s) return s.error();
    }
    for (double g : options.glosses) {
      if (!(g >= 0.0 && g <= 1.0)) return Error{"", "gloss " + std::to_string(g) + " is outside [0, 1]", true};
    }

    Preview preview;
    const int columns = options.glosses.empty() ? 1 : int(options.glosses.size());
    const int size = options.cell_size;
    for (int row = 0; row < int(materials.size()); ++row) {
      for (int column = 0; column < columns; ++column) {
        Material m = materials[row];
        if (!options.glosses.empty()) m.gloss = options.glosses[column];
        preview.cells.push_back({row, column, column * size, row * size, size, m});
      }
    }
    image::Image& img = preview.image;
    img.width = columns * size;
    img.height = int(materials.size()) * size;
    img.channels = 3;
    img.channel_names = {"R", "G", "B"};
    img.pixels.assign(img.sample_count(), float(kBackground));

    // 2×2 samples per pixel: smooth ball edges.
    constexpr int kSamples = 2;
    tbb::parallel_for(std::size_t(0), preview.cells.size(), [&](std::size_t index) {
      const Cell& cell = preview.cells[index];
      for (int py = 0; py < size; ++py) {
        for (int px = 0; px < size; ++px) {
          Vec3 sum(0.0);
          for (int sy = 0; sy < kSamples; ++sy) {
            for (int sx = 0; sx < kSamples; ++sx) {
              const double x = ((px + (sx + 0.5) / kSamples) / size * 2.0 - 1.0) / kBallRadius;
              const double z = (1.0 - (py + (sy + 0.5) / kSamples) / size * 2.0) / kBallRadius;
              const double r2 = x * x + z * z;
              if (r2 >= 1.0) {
                sum += Vec3(kBackground);
                continue;
              }
              const Vec3 n(x, std::sqrt(1.0 - r2), z);
              const Surface s = surface_at(cell.material, n, options.glosses.empty());
              for (int c = 0; c < 3; ++c) {
                sum[c] += s.mask * shade(*model, n, s.kd[c], s.ks[c], s.gloss, options.sky) + (1 - s.mask) * kBackground;
              }
            }
          }
          float* out = &img.pixels[(std::size_t(cell.y + py) * img.width + cell.x + px) * 3];
          for (int c = 0; c < 3; ++c) out[c] = float(sum[c] / (kSamples * kSamples));
        }
      }
    });
    return preview;
  });
}

}  // namespace matbake::preview
