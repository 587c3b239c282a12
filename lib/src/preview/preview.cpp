#include "matbake/preview.hpp"
#include "matbake/workflow.hpp"

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "matbake/shading_catalog.hpp"

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

}  // namespace

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
  return {std::move(name), sg.kd, sg.ks, sg.gloss};
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

Result<std::vector<Material>> load_materials(const std::filesystem::path& path) {
  return guarded(path.string(), [&]() -> Result<std::vector<Material>> {
    std::ifstream in(path);
    if (!in) return Error{path.string(), "cannot open"};
    std::vector<Material> materials;
    try {
      const nlohmann::json doc = nlohmann::json::parse(in);
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
              for (int c = 0; c < 3; ++c) sum[c] += shade(*model, n, cell.material.kd[c], cell.material.ks[c], cell.material.gloss, options.sky);
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
