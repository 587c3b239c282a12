// Combinations of features, walked whole:
// - every (layout × workflow × source map): a map the material has reaches every texture channel
//   that reads it, whichever workflow the sources are in and whichever the layout needs; a texture
//   whose maps the material does not have is not written;
// - every (format × bits × transfer) of a written texture: read back as the build reads it, the
//   same values within the encoding's step, or refused before anything is written.
#include <gtest/gtest.h>

#include <cmath>

#include "matbake/color.hpp"
#include "matbake/pack.hpp"
#include "matbake/workflow_maps.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::pack {
namespace {

constexpr int kSide = 2;

// A 2×2 map whose texels differ from each other and from every layout default (0, 0.5, 1).
image::Image distinct_map(int channels, float offset) {
  image::Image m;
  m.width = m.height = kSide;
  m.channels = channels;
  for (int i = 0; i < kSide * kSide * channels; ++i) m.pixels.push_back(offset + 0.07f * float(i));
  return m;
}

// A valid stored normal map: unit vectors n, stored 0.5 n + 0.5.
image::Image normal_map() {
  image::Image m = distinct_map(3, 0);
  const float n[4][3] = {{0.6f, 0, 0.8f}, {0, 0.6f, 0.8f}, {-0.28f, 0.96f * 0.6f, 0.96f * 0.8f}, {0, 0, 1}};
  for (int t = 0; t < 4; ++t) {
    for (int c = 0; c < 3; ++c) m.pixels[std::size_t(t * 3 + c)] = 0.5f * n[t][c] + 0.5f;
  }
  return m;
}

image::Image source_map(std::string_view name) {
  if (name == material::kNormal) return normal_map();
  const material::Source* source = material::find_source(name);
  return distinct_map(material::component_count(source->kind), 0.11f);
}

material::Maps material_with(const std::vector<std::string_view>& workflow_maps, std::string_view extra) {
  material::Maps m;
  m.width = m.height = kSide;
  for (std::string_view name : workflow_maps) m.maps.emplace(std::string(name), source_map(name));
  if (!extra.empty()) m.maps.emplace(std::string(extra), source_map(extra));
  return m;
}

double stored(const Channel& c, double x) { return c.transform == Transform::one_minus ? 1 - x : x; }

TEST(LayoutWalk, EveryGivenMapReachesEveryLayoutThatReadsIt) {
  const std::vector<std::vector<std::string_view>> workflows = {
      {material::kKd, material::kKs, material::kGloss}, {material::kBaseColor, material::kMetallic, material::kRoughness}};
  const std::vector<std::string_view> extras = {"", material::kMask, material::kOcclusion, material::kDetailMask,
                                                material::kNormal, material::kEmissive};
  int checked_channels = 0, skipped_textures = 0;
  for (const std::string& layout_name : builtin_layout_names()) {
    auto layout = find_layout(layout_name);
    ASSERT_TRUE(layout) << layout.error().to_string();
    for (const auto& workflow : workflows) {
      for (std::string_view extra : extras) {
        SCOPED_TRACE(layout_name + " with " + std::string(workflow[0]) + "… + " + std::string(extra));
        const material::Maps given = material_with(workflow, extra);
        auto in_layout = workflow::in_layout_workflow(given, *layout, workflow::kDefaultRoughnessMapping);
        ASSERT_TRUE(in_layout) << in_layout.error().to_string();
        const material::MapNames names = in_layout->maps.names();
        // The plan's rule, from names alone, agrees with the maps the conversion returned.
        EXPECT_EQ(workflow::names_in_layout_workflow(given.names(), *layout), names);
        auto textures = pack(*layout, in_layout->maps);
        ASSERT_TRUE(textures) << textures.error().to_string();
        for (std::size_t t = 0; t < layout->textures.size(); ++t) {
          const Texture& texture = layout->textures[t];
          bool reads_a_given_map = false;
          for (std::size_t c = 0; c < texture.channels.size(); ++c) {
            const Channel& channel = texture.channels[c];
            if (!names.contains(channel.source)) continue;
            reads_a_given_map = true;
            if (channel.source != extra) continue;  // the converted maps have their own tests
            const image::Image& map = given.maps.at(std::string(extra));
            for (std::size_t i = 0; i < kSide * kSide; ++i) {
              const double expected = stored(channel, map.pixels[i * std::size_t(map.channels) + std::size_t(channel.component)]);
              EXPECT_NEAR((*textures)[t].pixels[i * texture.channels.size() + c], expected, 1e-6)
                  << texture.name << " channel " << c << " texel " << i;
            }
            ++checked_channels;
          }
          EXPECT_EQ(texture_written(texture, names), reads_a_given_map) << texture.name;
          skipped_textures += !reads_a_given_map;
        }
      }
    }
  }
  EXPECT_GE(checked_channels, 34);  // each layout channel reading mask, occlusion, detail mask, normal or emissive, twice
  EXPECT_GT(skipped_textures, 0);   // gltf-pbr's emissive and normal without those maps
}

// The largest difference a write then read may make to a value in [0, 1]: half a code of the
// curve it is stored with (8-bit colour: the transfer's), or half's and float's rounding.
double encoding_step(image::SampleType type, color::Transfer stored_with, double value) {
  switch (type) {
    case image::SampleType::u8: {
      // Half a code in the encoded domain, as a linear difference (the curve's slope at value).
      const double encoded = color::encoded_from_linear(stored_with, value);
      return std::abs(color::linear_from_encoded(stored_with, std::min(1.0, encoded + 0.5 / 255)) - value) + 1e-6;
    }
    case image::SampleType::u16: return 0.5 / 65535 + 1e-7;
    case image::SampleType::half: return std::max(value, 6.1e-5) * std::ldexp(1.0, -11);
    case image::SampleType::f32: return 0;
  }
  return 0;
}

TEST(EncodingWalk, EveryFormatBitsAndTransferRoundTripsOrIsRefused) {
  const Layout layout{"walk", "", {{"colour", true, {{"base_color", 0}, {"base_color", 1}, {"base_color", 2}, {"mask", 0}}}}};
  material::Maps maps;
  maps.width = 16;
  maps.height = 4;
  image::Image colour = distinct_map(3, 0), mask = distinct_map(1, 0);
  colour.width = mask.width = 16;
  colour.height = mask.height = 4;
  colour.pixels.resize(16 * 4 * 3);
  mask.pixels.resize(16 * 4);
  for (std::size_t i = 0; i < colour.pixels.size(); ++i) colour.pixels[i] = float((i * 37) % 192) / 191.0f;
  for (std::size_t i = 0; i < mask.pixels.size(); ++i) mask.pixels[i] = float(i) / 63.0f;
  maps.maps.emplace("base_color", colour);
  maps.maps.emplace("mask", mask);
  test::TempDir dir;
  int written = 0, refused = 0;
  for (const char* format : {"png", "exr", "tif"}) {
    for (image::SampleType type : {image::SampleType::u8, image::SampleType::u16, image::SampleType::half, image::SampleType::f32}) {
      for (color::Transfer transfer : {color::Transfer::linear, color::Transfer::srgb, color::Transfer::gamma22}) {
        const std::string name = std::string(image::sample_type_name(type)) + "_" +
                                 std::string(color::transfer_name(transfer)) + "." + format;
        SCOPED_TRACE(name);
        const std::filesystem::path path = dir / name;
        auto result = write_textures(layout, maps, {{path.string()}, type, transfer, {}, {}, {}});
        const bool storable = !image::sample_type_problem(path, type);
        if (!storable) {
          ASSERT_FALSE(result);
          EXPECT_TRUE(result.error().usage);
          EXPECT_FALSE(std::filesystem::exists(path));
          EXPECT_EQ(test::list_folder(dir.path()).size(), std::size_t(written));  // no temporary left either
          ++refused;
          continue;
        }
        ASSERT_TRUE(result) << result.error().to_string();
        ++written;
        // Read back as a material source is: the file's own tag, else the depth rule.
        auto decode = decode_transfer(path, transfer);
        ASSERT_TRUE(decode) << decode.error().to_string();
        auto back = image::read_image(path, *decode);
        ASSERT_TRUE(back) << back.error().to_string();
        ASSERT_EQ(back->channels, 4);
        const color::Transfer stored_with = type == image::SampleType::u8 ? transfer : color::Transfer::linear;
        for (std::size_t t = 0; t < 64; ++t) {
          for (std::size_t c = 0; c < 4; ++c) {
            const double expected = c < 3 ? colour.pixels[t * 3 + c] : mask.pixels[t];
            const color::Transfer curve = c < 3 ? stored_with : color::Transfer::linear;
            ASSERT_NEAR(back->pixels[t * 4 + c], expected, encoding_step(type, curve, expected)) << t << " " << c;
          }
        }
      }
    }
  }
  EXPECT_EQ(written, 3 * 2 + 3 * 2 + 3 * 4);  // PNG 8/16, EXR half/float, TIFF all four; × 3 transfers
  EXPECT_EQ(refused, 3 * 2 + 3 * 2);
}

}  // namespace
}  // namespace matbake::pack
