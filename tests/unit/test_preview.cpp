// Material-ball previews: layout, a closed-form pixel, the metal-rough relation, refusals.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>

#include "matbake/preview.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::preview {
namespace {

TEST(Preview, GridLayoutAndBackground) {
  Options options;
  options.cell_size = 16;
  options.glosses = {0.25, 0.5, 0.75, 1.0};
  auto result = render({{"a", shading::Vec3(0.5), shading::Vec3(0.04), 0.5, nullptr},
                        {"b", shading::Vec3(0.0), shading::Vec3(0.9), 0.5, nullptr}},
                       options);
  ASSERT_TRUE(result) << result.error().to_string();
  EXPECT_EQ(result->image.width, 64);
  EXPECT_EQ(result->image.height, 32);
  ASSERT_EQ(result->cells.size(), 8u);
  EXPECT_EQ(result->cells[5].row, 1);
  EXPECT_EQ(result->cells[5].column, 1);
  EXPECT_EQ(result->cells[5].x, 16);
  EXPECT_EQ(result->cells[5].material.gloss, 0.5);
  EXPECT_EQ(result->cells[5].material.name, "b");
  EXPECT_FLOAT_EQ(result->image.pixels[0], float(kBackground));  // a corner is outside every ball
}

TEST(Preview, LambertBallCentreHasTheClosedFormRadiance) {
  // Centre pixel: n = v = +y. With ks = 0 only diffuse remains:
  // kd · lerp(E_lower, E_upper, 1/2) + kd · Σ E_i max(n·l_i, 0).
  Options options;
  options.model = "lambert";
  options.cell_size = 63;  // odd: the centre pixel's 2×2 samples sit symmetrically about the axis
  auto result = render({{"white", shading::Vec3(0.7), shading::Vec3(0.0), 0.5, nullptr}}, options);
  ASSERT_TRUE(result);
  double expected = 0.7 * (options.sky.lower + options.sky.upper) / 2;
  for (const auto& light : lights()) expected += 0.7 * light.irradiance * std::max(light.direction.y, 0.0);
  // The samples' first-order offsets cancel; what remains is second order, below 1e-4.
  const auto& img = result->image;
  const float centre = img.pixels[(std::size_t(31) * img.width + 31) * 3];
  EXPECT_NEAR(centre, expected, 1e-4 * expected);
}

TEST(Preview, MetalRoughRelation) {
  const Material gold = from_metal_rough("gold", {1.0, 0.78, 0.34}, 1.0, 0.3);
  EXPECT_EQ(gold.kd, shading::Vec3(0.0));
  EXPECT_EQ(gold.ks, shading::Vec3(1.0, 0.78, 0.34));
  const Material plastic = from_metal_rough("plastic", {0.5, 0.2, 0.1}, 0.0, 0.3);
  EXPECT_EQ(plastic.kd, shading::Vec3(0.5, 0.2, 0.1));
  EXPECT_EQ(plastic.ks, shading::Vec3(0.04));
  // roughness r: α = r², e = 2/α² − 2, g = log2(e)/12.
  EXPECT_NEAR(gold.gloss, std::log2(2.0 / std::pow(0.09, 2) - 2.0) / 12.0, 1e-12);
  EXPECT_EQ(from_metal_rough("rough", shading::Vec3(0.5), 0.0, 1.0).gloss, 0.0);
  EXPECT_EQ(from_metal_rough("mirror", shading::Vec3(0.5), 0.0, 0.0).gloss, 1.0);
}

TEST(Preview, BadParametersAreRefused) {
  Options options;
  auto gloss = render({{"x", shading::Vec3(0.5), shading::Vec3(0.04), 1.5, nullptr}}, options);
  ASSERT_FALSE(gloss);
  EXPECT_EQ(gloss.error().message, "material 'x': gloss 1.500000 is outside [0, 1]");
  EXPECT_TRUE(gloss.error().usage);
  auto negative = render({{"y", shading::Vec3(-0.1, 0.5, 0.5), shading::Vec3(0.04), 0.5, nullptr}}, options);
  ASSERT_FALSE(negative);
  EXPECT_EQ(negative.error().message.rfind("material 'y': kd -0.1,0.5,0.5 is outside [0, 1]", 0), 0u)
      << negative.error().message;
  auto nan = render({{"z", shading::Vec3(0.5), shading::Vec3(std::nan("")), 0.5, nullptr}}, options);
  EXPECT_FALSE(nan);
  options.model = "nonsense";
  EXPECT_FALSE(render({{"w", shading::Vec3(0.5), shading::Vec3(0.04), 0.5, nullptr}}, options));
}

TEST(Preview, MaterialFiles) {
  test::TempDir dir;
  test::write_bytes(dir / "ok.json",
                    R"([{"name": "gold", "base_color": [1, 0.78, 0.34], "metallic": 1, "roughness": 0.3},
                        {"name": "paint", "kd": [0.2, 0.3, 0.5], "ks": [0.04, 0.04, 0.04], "gloss": 0.6}])");
  auto ok = load_materials(dir / "ok.json");
  ASSERT_TRUE(ok) << ok.error().to_string();
  ASSERT_EQ(ok->size(), 2u);
  EXPECT_EQ((*ok)[1].gloss, 0.6);
  test::write_bytes(dir / "broken.json", "[{\"name\": ");
  auto broken = load_materials(dir / "broken.json");
  ASSERT_FALSE(broken);
  EXPECT_EQ(broken.error().message.rfind("invalid material JSON", 0), 0u);
  test::write_bytes(dir / "bad.json", R"([{"name": "x", "kd": [2, 0, 0], "ks": [0, 0, 0], "gloss": 0.5}])");
  auto bad = load_materials(dir / "bad.json");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().path, (dir / "bad.json").string());
  EXPECT_FALSE(bad.error().usage);
}

// Source maps of `width` × 1 texels: `kd` per texel (grey), the rest constant.
material::Maps grey_maps(const std::vector<float>& kd, float ks, float gloss) {
  material::Maps maps;
  maps.width = int(kd.size()), maps.height = 1;
  const auto map = [&](int channels, const std::vector<float>& per_texel) {
    image::Image im;
    im.width = maps.width, im.height = 1, im.channels = channels;
    for (float v : per_texel) im.pixels.insert(im.pixels.end(), std::size_t(channels), v);
    return im;
  };
  maps.maps["kd"] = map(3, kd);
  maps.maps["ks"] = map(3, std::vector<float>(kd.size(), ks));
  maps.maps["gloss"] = map(1, std::vector<float>(kd.size(), gloss));
  return maps;
}

// A uniform texture renders as its constant; 1×1 maps are constants.
TEST(Preview, UniformTexturesRenderAsTheirConstant) {
  Options options;
  options.cell_size = 24;
  auto constant = render({{"c", shading::Vec3(0.3f), shading::Vec3(0.04f), double(0.6f), nullptr}}, options);
  auto one = material_from_maps("one", grey_maps({0.3f}, 0.04f, 0.6f));
  ASSERT_TRUE(one) << one.error().to_string();
  EXPECT_FALSE(one->textures);
  auto uniform = material_from_maps("uniform", grey_maps(std::vector<float>(8, 0.3f), 0.04f, 0.6f));
  ASSERT_TRUE(uniform) << uniform.error().to_string();
  ASSERT_TRUE(uniform->textures);
  EXPECT_NEAR(uniform->kd.x, 0.3, 1e-7);  // the mean, for the sidecar
  auto textured = render({*uniform}, options);
  ASSERT_TRUE(constant && textured);
  for (std::size_t i = 0; i < constant->image.pixels.size(); ++i) {
    EXPECT_NEAR(textured->image.pixels[i], constant->image.pixels[i], 1e-6) << i;
  }
}

// The texture is where the UV says: u = 0.5 faces the camera, u < 0.5 on the ball's left (−x).
// kd 0 on the left half of the texture, 1 on the right: the ball's left is darker than its right,
// and a mask of 0 leaves the background.
TEST(Preview, TexturesFollowTheBallsUv) {
  Options options;
  options.model = "lambert";
  options.cell_size = 32;
  std::vector<float> halves(64, 0.0f);
  std::fill(halves.begin() + 32, halves.end(), 1.0f);
  auto m = material_from_maps("halves", grey_maps(halves, 0.0f, 0.5f));
  ASSERT_TRUE(m) << m.error().to_string();
  auto result = render({*m}, options);
  ASSERT_TRUE(result);
  const auto pixel = [&](int x, int y) { return result->image.pixels[(std::size_t(y) * 32 + std::size_t(x)) * 3]; };
  EXPECT_LT(pixel(10, 16), 0.05f);  // left of the centre: kd ≈ 0 (only the background-free ball, black)
  EXPECT_GT(pixel(22, 16), 0.3f);   // right: kd ≈ 1
  material::Maps masked = grey_maps({0.5f, 0.5f}, 0.04f, 0.5f);
  image::Image mask;
  mask.width = 2, mask.height = 1, mask.channels = 1, mask.pixels = {0.0f, 0.0f};
  masked.maps["mask"] = mask;
  auto invisible = material_from_maps("masked", masked);
  ASSERT_TRUE(invisible);
  auto hidden = render({*invisible}, options);
  ASSERT_TRUE(hidden);
  for (float v : hidden->image.pixels) EXPECT_FLOAT_EQ(v, float(kBackground));
}

TEST(Preview, MetalRoughMapsAndRefusals) {
  material::Maps maps;
  maps.width = 1, maps.height = 1;
  image::Image base;
  base.width = 1, base.height = 1, base.channels = 3, base.pixels = {1.0f, 0.78f, 0.34f};
  maps.maps["base_color"] = base;
  auto gold = material_from_maps("gold", maps);  // metallic 0 and roughness 0.5 unless given
  ASSERT_TRUE(gold) << gold.error().to_string();
  const Material expected = from_metal_rough("gold", shading::Vec3(1.0f, 0.78f, 0.34f), 0, 0.5);
  EXPECT_NEAR(gold->kd.y, expected.kd.y, 1e-6);
  EXPECT_NEAR(gold->ks.x, expected.ks.x, 1e-6);
  EXPECT_NEAR(gold->gloss, expected.gloss, 1e-6);
  maps.maps["kd"] = base;
  EXPECT_FALSE(material_from_maps("both", maps));
}

}  // namespace
}  // namespace matbake::preview
