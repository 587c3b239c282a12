#pragma once
// Material balls: spheres under Schüler's two-hemisphere light plus two directional lights, one
// cell per (material, gloss), rendered with any catalog model into a linear RGB image.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "matbake/image.hpp"
#include "matbake/pack.hpp"
#include "matbake/result.hpp"
#include "matbake/shading.hpp"

namespace matbake::preview {

struct Material {
  std::string name;
  shading::Vec3 kd{0.5};   // diffuse colour, linear (of a texture: its mean)
  shading::Vec3 ks{0.04};  // specular colour (F0), linear (of a texture: its mean)
  double gloss = 0.5;      // g in [0, 1]; e = 2^(12 g) (of a texture: its mean)
  // Schüler maps (kd, ks, gloss, mask; linear) sampled over the ball at its UV: u around the vertical
  // axis (0.5 faces the camera), v from the top pole (0) to the bottom (1), bilinear, u wrapping.
  // The mask blends the ball over the background. Absent maps: the constants above.
  std::shared_ptr<const material::Maps> textures;
};

// A material from source maps as `matbake pack` reads them: Schüler's (kd, ks, gloss, mask; the
// defaults above for those not given) or metal-rough (base_color with metallic 0 and roughness 0.5
// unless given, converted per texel as from_metal_rough does). 1×1 maps are constants.
Result<Material> material_from_maps(std::string name, const material::Maps& maps);

// The metalness workflow's relation (PBR notes): kd = base (1 − m), ks = lerp(0.04, base, m);
// gloss from glTF roughness by the Walter mapping (workflow::gloss_from_roughness).
Material from_metal_rough(std::string name, shading::Vec3 base_color, double metallic, double roughness);

// Refuses what no renderer should take: colours outside [0, 1] or NaN, gloss outside [0, 1].
Status check(const Material& material);

// [{"name": "...", "kd": [r, g, b], "ks": [r, g, b], "gloss": g}, ...] or with "base_color",
// "metallic", "roughness" instead of kd/ks/gloss.
Result<std::vector<Material>> load_materials(const std::filesystem::path& path);

// The light rig: z up (Schüler's hemisphere axis), camera on +y looking at −y, x to the right.
struct DirectionalLight {
  shading::Vec3 direction;  // unit, towards the light
  double irradiance;        // in Schüler's units (the 1/π folded in)
};
const std::vector<DirectionalLight>& lights();
inline constexpr double kBackground = 0.02;  // linear value around the balls

struct Options {
  std::string model = "schuler-optimized";  // a shading::models() name
  int cell_size = 128;                       // pixels per ball cell
  std::vector<double> glosses;               // columns; empty: one column at each material's gloss
  shading::HemisphereLight sky{0.12, 0.8};
};

struct Cell {
  int row = 0, column = 0, x = 0, y = 0, size = 0;
  Material material;  // with the cell's gloss
};

struct Preview {
  image::Image image;  // linear RGB
  std::vector<Cell> cells;
};

Result<Preview> render(const std::vector<Material>& materials, const Options& options);

}  // namespace matbake::preview
