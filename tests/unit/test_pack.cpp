// Layouts: the presets' channel assignments value by value, parse errors, pack/unpack inverses,
// source loading (sizes, resize, constants).
#include <gtest/gtest.h>

#include <zlib.h>

#include <cmath>

#include "matbake/color.hpp"
#include "matbake/pack.hpp"
#include "support/files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::pack {
namespace {

using test::TempDir;

// Two texels, every source with different values (and texel 1 different from texel 0).
material::Maps all_sources() {
  std::vector<SourceInput> inputs = {
      {"kd", {}, {0.11, 0.12, 0.13}}, {"ks", {}, {0.21, 0.22, 0.23}}, {"mask", {}, {0.9}},
      {"gloss", {}, {0.35}},          {"base_color", {}, {0.41, 0.42, 0.43}}, {"metallic", {}, {0.7}},
      {"roughness", {}, {0.25}},      {"occlusion", {}, {0.6}},               {"detail_mask", {}, {0.4}},
      {"normal", {}, {0.5, 0.5, 1.0}}, {"emissive", {}, {0.51, 0.52, 0.53}}};
  auto maps = load_sources(inputs, {.width = 2, .height = 1});
  EXPECT_TRUE(maps) << maps.error().to_string();
  for (auto& [name, map] : maps->maps) {
    for (std::size_t i = std::size_t(map.channels); i < map.pixels.size(); ++i) map.pixels[i] *= 0.5f;
  }
  return *maps;
}

std::vector<float> texel(const image::Image& image, int i) {
  return {image.pixels.begin() + i * image.channels, image.pixels.begin() + (i + 1) * image.channels};
}

void expect_texel(const image::Image& image, int i, std::vector<double> expected, const std::string& what) {
  const auto got = texel(image, i);
  ASSERT_EQ(got.size(), expected.size()) << what;
  for (std::size_t c = 0; c < got.size(); ++c) EXPECT_NEAR(got[c], expected[c], 1e-6) << what << " channel " << c;
}

TEST(Layouts, EveryPresetParses) {
  const auto names = builtin_layout_names();
  for (const char* name : {"schuler", "gltf-metal-rough", "gltf-orm", "gltf-pbr", "unreal-orm", "unity-hdrp", "unity-urp"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    auto layout = find_layout(name);
    ASSERT_TRUE(layout) << layout.error().to_string();
    EXPECT_EQ(layout->name, name);
  }
}

TEST(Layouts, PresetChannelsValueByValue) {
  const material::Maps s = all_sources();
  const auto packed = [&](const char* name) {
    auto images = pack(*find_layout(name), s);
    EXPECT_TRUE(images) << name;
    return *images;
  };
  for (int i : {0, 1}) {
    const double h = i ? 0.5 : 1.0;  // texel 1 holds half of texel 0's values
    auto schuler = packed("schuler");
    expect_texel(schuler[0], i, {0.11 * h, 0.12 * h, 0.13 * h, 0.9 * h}, "schuler A");
    expect_texel(schuler[1], i, {0.21 * h, 0.22 * h, 0.23 * h, 0.35 * h}, "schuler B");
    auto gltf = packed("gltf-metal-rough");
    expect_texel(gltf[0], i, {0.41 * h, 0.42 * h, 0.43 * h, 0.9 * h}, "glTF base colour");
    expect_texel(gltf[1], i, {0, 0.25 * h, 0.7 * h}, "glTF metallicRoughness");
    expect_texel(packed("gltf-orm")[1], i, {0.6 * h, 0.25 * h, 0.7 * h}, "glTF ORM");
    auto unreal = packed("unreal-orm");
    expect_texel(unreal[0], i, {0.41 * h, 0.42 * h, 0.43 * h}, "Unreal base colour");
    expect_texel(unreal[1], i, {0.6 * h, 0.25 * h, 0.7 * h}, "Unreal ORM");
    expect_texel(packed("unity-hdrp")[1], i, {0.7 * h, 0.6 * h, 0.4 * h, 1 - 0.25 * h}, "HDRP mask map");
    expect_texel(packed("unity-urp")[1], i, {0.7 * h, 0, 0, 1 - 0.25 * h}, "URP metallic gloss");
  }
  EXPECT_EQ(packed("schuler")[0].alpha_channel, 3);
  EXPECT_EQ(packed("gltf-orm")[1].alpha_channel, -1);
}

TEST(Layouts, DefaultsAndMissingSources) {
  material::Maps s = all_sources();
  s.maps.erase("occlusion");
  s.maps.erase("mask");
  auto orm = pack(*find_layout("gltf-orm"), s);
  ASSERT_TRUE(orm);
  expect_texel((*orm)[0], 0, {0.41, 0.42, 0.43, 1.0}, "mask defaults to 1");
  expect_texel((*orm)[1], 0, {1.0, 0.25, 0.7}, "occlusion defaults to 1");
  s.maps.erase("roughness");
  auto missing = pack(*find_layout("gltf-orm"), s);
  ASSERT_FALSE(missing);
  EXPECT_TRUE(missing.error().usage);
  EXPECT_EQ(missing.error().message, "layout gltf-orm needs roughness");
}

TEST(Layouts, UnpackInvertsPackIncludingOneMinus) {
  const material::Maps s = all_sources();
  for (const std::string& name : builtin_layout_names()) {
    const Layout layout = *find_layout(name);
    auto textures = pack(layout, s);
    ASSERT_TRUE(textures);
    const std::vector<std::string> paths(textures->size(), "t");
    auto back = unpack(layout, *textures, paths);
    ASSERT_TRUE(back) << name;
    for (const std::string& source : layout_sources(layout)) {
      const image::Image* got = back->find(source);
      ASSERT_NE(got, nullptr) << name << " " << source;
      const image::Image* want = s.find(source);
      for (std::size_t i = 0; i < got->pixels.size(); ++i) {
        EXPECT_NEAR(got->pixels[i], want->pixels[i], 1e-7) << name << " " << source;
      }
    }
  }
}

TEST(Layouts, ParseErrorsNameTheFileAndTheProblem) {
  const std::pair<const char*, const char*> cases[] = {
      {"{", "not a valid layout (JSON)"},
      {R"({"textures": []})", "a layout needs a non-empty \"textures\" array"},
      {R"({"textures": [{"name": "t", "channels": [{"source": "albedo"}]}]})", "unknown source \"albedo\""},
      {R"({"textures": [{"name": "t", "channels": [{"source": "gloss", "component": 1}]}]})",
       "component 1 of \"gloss\", which has 1"},
      {R"({"textures": [{"name": "t", "channels": [{"source": "gloss", "transform": "square"}]}]})",
       "\"transform\" must be \"identity\" or \"one_minus\""},
      {R"({"textures": [{"name": "t", "channels": [{}]}]})", "needs a \"source\" or a \"value\""},
      {R"({"textures": [{"name": "t", "color": true, "channels": [{"value": 0}]}]})", "a colour texture has RGB"},
      {R"({"textures": [{"name": "t", "channels": [{"value": 0}, {"value": 0}, {"value": 0}, {"value": 0}, {"value": 0}]}]})",
       "1 to 4 channels"},
      {R"({"textures": [{"name": "t", "channels": [{"source": "gloss", "gain": 2}]}]})", "unknown key \"gain\""},
  };
  for (const auto& [json, message] : cases) {
    auto layout = parse_layout(json, "mine.json");
    ASSERT_FALSE(layout) << json;
    EXPECT_EQ(layout.error().path, "mine.json");
    EXPECT_NE(layout.error().message.find(message), std::string::npos) << layout.error().message;
  }
  auto missing = find_layout("no-such-layout");
  ASSERT_FALSE(missing);
  EXPECT_TRUE(missing.error().usage);
}

TEST(Sources, ConstantsFillTheSizeOfTheFiles) {
  TempDir dir;
  test::write_raw(dir / "gloss.png", 3, 2, 1, "uint8", {0, 51, 102, 153, 204, 255});
  auto maps = load_sources({{"gloss", dir / "gloss.png", {}}, {"kd", {}, {0.5}}}, {});
  ASSERT_TRUE(maps) << maps.error().to_string();
  EXPECT_EQ(maps->width, 3);
  EXPECT_EQ(maps->height, 2);
  EXPECT_EQ(maps->find("kd")->pixels, std::vector<float>(18, 0.5f));
  EXPECT_FLOAT_EQ(maps->find("gloss")->pixels[1], 0.2f);  // scalar sources are linear
  // A single constant with no file: 1×1.
  auto one = load_sources({{"gloss", {}, {0.5}}}, {});
  ASSERT_TRUE(one);
  EXPECT_EQ(one->width * one->height, 1);
}

TEST(Sources, ColourFilesDecodeBy8BitRuleGreyRepeats) {
  TempDir dir;
  test::write_raw(dir / "grey.png", 1, 1, 1, "uint8", {188});
  test::write_raw(dir / "rgb16.png", 1, 1, 3, "uint16", {0, 32768, 65535});
  auto maps = load_sources({{"kd", dir / "grey.png", {}}, {"ks", dir / "rgb16.png", {}}}, {.transfer = color::Transfer::gamma22});
  ASSERT_TRUE(maps);
  const float grey = float(std::pow(188 / 255.0, 2.2));
  EXPECT_EQ(maps->find("kd")->pixels, std::vector<float>(3, grey));
  EXPECT_FLOAT_EQ(maps->find("ks")->pixels[1], 32768 / 65535.0f);  // 16-bit: linear
}

// A PNG chunk `type` with `data` inserted after IHDR (a tag matbake's writer does not make).
std::string with_chunk_after_header(const std::string& png, const std::string& type, const std::string& data) {
  std::string chunk;
  for (int shift = 24; shift >= 0; shift -= 8) chunk += char((data.size() >> shift) & 0xff);
  const std::string body = type + data;
  chunk += body;
  const unsigned long crc = crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()));
  for (int shift = 24; shift >= 0; shift -= 8) chunk += char((crc >> shift) & 0xff);
  return png.substr(0, 33) + chunk + png.substr(33);
}

// A colour file's own tag decides how it is decoded (the depth rule only for untagged files):
// a 16-bit PNG written sRGB-encoded and tagged by `convert --to srgb --bits 16` is read as sRGB,
// an 8-bit one tagged linear as linear, a cICP chunk outranks the rest; `decode` overrides the
// tag, with a note naming the file.
TEST(Sources, ColourFilesDecodeByTheirOwnTag) {
  TempDir dir;
  image::Image colour;
  colour.width = 3;
  colour.height = 1;
  colour.channels = 3;
  colour.pixels = {0.0f, 0.2f, 0.9f, 0.05f, 0.5f, 1.0f, 0.3f, 0.01f, 0.7f};
  struct Case {
    const char* file;
    image::SampleType type;
    color::Transfer encoded;
    const char* tag;
  };
  const Case cases[] = {{"srgb16.png", image::SampleType::u16, color::Transfer::srgb, "sRGB"},
                        {"gamma16.png", image::SampleType::u16, color::Transfer::gamma22, "Gamma2.2"},
                        {"linear8.png", image::SampleType::u8, color::Transfer::linear, "Linear"},
                        {"srgb8.png", image::SampleType::u8, color::Transfer::srgb, "sRGB"}};
  for (const Case& c : cases) {
    image::WriteOptions options{.colour = c.encoded, .type = c.type, .colorspace = c.tag};
    ASSERT_TRUE(image::write_image(colour, dir / c.file, options));
    // `transfer` (gamma 2.2) is for untagged 8-bit files: the tag wins over it and over the depth.
    auto maps = load_sources({{"kd", dir / c.file, {}}}, {.transfer = color::Transfer::gamma22});
    ASSERT_TRUE(maps) << maps.error().to_string();
    const double step = c.type == image::SampleType::u8 ? 0.02 : 2e-4;
    for (std::size_t i = 0; i < colour.pixels.size(); ++i) {
      EXPECT_NEAR(maps->find("kd")->pixels[i], colour.pixels[i], step) << c.file << " " << i;
    }
    auto tagged = decode_transfer(dir / c.file, color::Transfer::gamma22);
    ASSERT_TRUE(tagged);
    EXPECT_EQ(*tagged, c.encoded) << c.file;
  }
  // cICP transfer 8 (linear) outranks the sRGB chunk beside it.
  test::write_bytes(dir / "cicp.png", with_chunk_after_header(test::read_bytes(dir / "srgb16.png"), "cICP",
                                                               std::string("\x01\x08\x00\x01", 4)));
  EXPECT_EQ(*decode_transfer(dir / "cicp.png", color::Transfer::srgb), color::Transfer::linear);
  // Untagged: the depth rule.
  test::write_raw(dir / "plain16.png", 1, 1, 3, "uint16", {0, 32768, 65535});
  EXPECT_EQ(*decode_transfer(dir / "plain16.png", color::Transfer::srgb), color::Transfer::linear);
  // An explicit decode wins, and says so naming the file; agreeing files say nothing.
  const std::vector<SourceInput> inputs = {{"kd", dir / "srgb16.png", {}}, {"ks", dir / "linear8.png", {}}};
  const auto notes = decode_overrides(inputs, {.decode = color::Transfer::linear});
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0], (dir / "srgb16.png").string() + ": decoded as linear as asked, though its sRGB chunk says srgb");
  auto decoded = load_sources(inputs, {.decode = color::Transfer::linear});
  ASSERT_TRUE(decoded);
  EXPECT_NEAR(decoded->find("kd")->pixels[1], color::encoded_from_linear(color::Transfer::srgb, 0.2), 2e-4);
}

// One channel of a file (gloss from the alpha of a spec-gloss texture, roughness from G of an ORM),
// its RGB, or as stored; a channel the file lacks is an error naming it.
TEST(Sources, ChannelsOfAFile) {
  TempDir dir;
  test::write_raw(dir / "sg.png", 2, 1, 4, "uint8", {10, 20, 30, 40, 50, 60, 70, 80});
  test::write_raw(dir / "orm.png", 1, 1, 3, "uint8", {255, 51, 102});
  test::write_raw(dir / "grey.png", 1, 1, 1, "uint8", {51});
  auto text = source_from_text("gloss", "sg.png:a", dir.path());
  ASSERT_TRUE(text);
  EXPECT_EQ(text->file, dir / "sg.png");
  EXPECT_EQ(text->channels, FileChannels::a);
  EXPECT_EQ(source_from_text("gloss", "sg.png", dir.path())->channels, FileChannels::as_stored);
  EXPECT_EQ(source_from_text("gloss", "odd:name.png", dir.path())->file, dir / "odd:name.png");  // not a channel name
  EXPECT_EQ(source_from_text("ks", "sg.png:rgb", dir.path())->channels, FileChannels::rgb);

  const MaterialOptions linear{.transfer = color::Transfer::linear};
  auto maps = load_sources({{"gloss", dir / "sg.png", {}, FileChannels::a},
                            {"ks", dir / "sg.png", {}, FileChannels::rgb},
                            {"kd", dir / "sg.png", {}, FileChannels::g}},
                           linear);
  ASSERT_TRUE(maps) << maps.error().to_string();
  EXPECT_EQ(maps->find("gloss")->pixels, (std::vector<float>{40 / 255.0f, 80 / 255.0f}));
  EXPECT_EQ(maps->find("ks")->pixels, (std::vector<float>{10 / 255.0f, 20 / 255.0f, 30 / 255.0f, 50 / 255.0f, 60 / 255.0f, 70 / 255.0f}));
  EXPECT_EQ(maps->find("kd")->pixels, (std::vector<float>{20 / 255.0f, 20 / 255.0f, 20 / 255.0f, 60 / 255.0f, 60 / 255.0f, 60 / 255.0f}));
  auto orm = load_sources({{"roughness", dir / "orm.png", {}, FileChannels::g}, {"metallic", dir / "orm.png", {}, FileChannels::b}}, {});
  ASSERT_TRUE(orm);
  EXPECT_FLOAT_EQ(orm->find("roughness")->pixels[0], 0.2f);  // scalar sources are linear
  EXPECT_FLOAT_EQ(orm->find("metallic")->pixels[0], 0.4f);

  const auto error_of = [&](const SourceInput& in) { return load_sources({in}, {}).error().to_string(); };
  EXPECT_EQ(error_of({"gloss", dir / "orm.png", {}, FileChannels::a}),
            (dir / "orm.png").string() + ": has no alpha channel (3 channels) for gloss");
  EXPECT_EQ(error_of({"gloss", dir / "grey.png", {}, FileChannels::g}),
            (dir / "grey.png").string() + ": has no channel g (1 channels) for gloss");
  EXPECT_EQ(error_of({"gloss", dir / "orm.png", {}, FileChannels::rgb}), (dir / "orm.png").string() + ": gloss takes one channel, not rgb");
}

// A packed texture without the alpha its layout has a default for (Schüler's A as an RGB diffuse):
// the mask takes the default; a missing channel with no default is still an error.
TEST(Sources, PackedTexturesWithoutAlphaTakeTheLayoutsDefault) {
  TempDir dir;
  test::write_raw(dir / "a.png", 1, 1, 3, "uint8", {51, 102, 153});
  test::write_raw(dir / "b.png", 1, 1, 3, "uint8", {10, 10, 10});
  const Layout schuler = *find_layout("schuler");
  auto maps = read_packed(schuler, {dir / "a.png", dir / "b.png"}, {.transfer = color::Transfer::linear});
  ASSERT_FALSE(maps);  // B's gloss has no default
  EXPECT_EQ(maps.error().to_string(), (dir / "b.png").string() + ": 3 channels; layout schuler texture b has 4 and channel 3 (gloss) has no default");
  test::write_raw(dir / "b.png", 1, 1, 4, "uint8", {10, 10, 10, 128});
  maps = read_packed(schuler, {dir / "a.png", dir / "b.png"}, {.transfer = color::Transfer::linear});
  ASSERT_TRUE(maps) << maps.error().to_string();
  EXPECT_EQ(maps->find("mask")->pixels, std::vector<float>{1.0f});
  EXPECT_FLOAT_EQ(maps->find("kd")->pixels[1], 0.4f);
}

// Normal maps: decoded to vectors, green flipped for DirectX's convention, renormalised and stored
// as glTF does (0.5·n + 0.5, +Y up); a map that is not tangent-space (a height map) is refused.
TEST(Sources, NormalMapsAreFlippedRenormalisedAndChecked) {
  TempDir dir;
  test::write_raw(dir / "n.png", 2, 1, 3, "uint8", {128, 64, 230, 128, 128, 255});
  for (const NormalConvention convention : {NormalConvention::opengl, NormalConvention::directx}) {
    auto maps = load_sources({{"normal", dir / "n.png", {}}}, {.normal_y = convention});
    ASSERT_TRUE(maps) << maps.error().to_string();
    double n[3] = {2 * 128 / 255.0 - 1, 2 * 64 / 255.0 - 1, 2 * 230 / 255.0 - 1};
    if (convention == NormalConvention::directx) n[1] = -n[1];
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const std::vector<float>& got = maps->find("normal")->pixels;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[std::size_t(c)], 0.5 * n[c] / length + 0.5, 1e-6) << c;
    EXPECT_NEAR(got[5], 1.0, 1e-5);  // (128, 128, 255): +Z within a code, renormalised to it
  }
  // The same through a packed layout (gltf-pbr's normal texture).
  const Layout pbr = *find_layout("gltf-pbr");
  test::write_raw(dir / "base.png", 2, 1, 4, "uint8", std::vector<double>(8, 200));
  test::write_raw(dir / "orm.png", 2, 1, 3, "uint8", std::vector<double>(6, 100));
  test::write_raw(dir / "e.png", 2, 1, 3, "uint8", std::vector<double>(6, 0));
  auto packed = read_packed(pbr, {dir / "base.png", dir / "orm.png", dir / "n.png", dir / "e.png"}, {.normal_y = NormalConvention::directx});
  ASSERT_TRUE(packed) << packed.error().to_string();
  EXPECT_GT(packed->find("normal")->pixels[1], 0.5f);  // green 64 under DirectX points up
  // A grey height map: most texels below the surface or far from unit length.
  test::write_raw(dir / "height.png", 2, 1, 3, "uint8", {100, 100, 100, 90, 90, 90});
  auto refused = load_sources({{"normal", dir / "height.png", {}}}, {});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().to_string(), (dir / "height.png").string() + ": normal: not a tangent-space normal map: 100% of its "
                                         "texels point below the surface (z < 0) or are far from unit length (an object-space "
                                         "normal map, or a height or colour map?)");
}

TEST(Sources, DifferentSizesAreAnErrorUnlessResized) {
  TempDir dir;
  test::write_raw(dir / "big.png", 4, 4, 1, "uint8", std::vector<double>(16, 128));
  test::write_raw(dir / "small.png", 2, 2, 1, "uint8", std::vector<double>(4, 51));
  const std::vector<SourceInput> inputs = {{"gloss", dir / "big.png", {}}, {"mask", dir / "small.png", {}}};
  auto refused = load_sources(inputs, {});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().path, (dir / "small.png").string());
  EXPECT_EQ(refused.error().message, "2x2, but " + (dir / "big.png").string() +
                                         " is 4x4 (resizing resamples to the largest)");
  auto resized = load_sources(inputs, {.resize = true});
  ASSERT_TRUE(resized);
  for (float v : resized->find("mask")->pixels) EXPECT_NEAR(v, 0.2f, 1e-6);  // a constant stays constant
}

// A packed pair with sources given beside it: each source replaces the unpacked map of its name,
// constants at the pair's size, a file of another size resized only when asked.
TEST(Sources, SourcesBesidePackedTexturesReplaceTheirMaps) {
  TempDir dir;
  // Schüler A = kd (linear 8-bit: written as linear codes) + mask, B = ks + gloss; 4x2.
  const Layout schuler = *find_layout("schuler");
  std::vector<double> a(4 * 2 * 4, 102), b(4 * 2 * 4, 204);
  test::write_raw(dir / "a.png", 4, 2, 4, "uint8", a);
  test::write_raw(dir / "b.png", 4, 2, 4, "uint8", b);
  test::write_raw(dir / "gloss.png", 2, 1, 1, "uint8", {51, 51});
  const std::vector<std::filesystem::path> pair = {dir / "a.png", dir / "b.png"};
  const MaterialOptions linear{.transfer = color::Transfer::linear};

  auto constant = load_material({{"gloss", {}, {0.25}}}, &schuler, pair, linear);
  ASSERT_TRUE(constant) << constant.error().to_string();
  EXPECT_EQ(constant->width, 4);
  EXPECT_EQ(constant->height, 2);
  for (float v : constant->find("gloss")->pixels) EXPECT_FLOAT_EQ(v, 0.25f);
  for (float v : constant->find("mask")->pixels) EXPECT_FLOAT_EQ(v, 0.4f);  // 102/255, from the pair
  EXPECT_FLOAT_EQ(constant->find("ks")->pixels[0], 0.8f);                   // 204/255

  const std::vector<SourceInput> small = {{"gloss", dir / "gloss.png", {}}};
  auto refused = load_material(small, &schuler, pair, linear);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().path, (dir / "a.png").string());
  EXPECT_EQ(refused.error().message, "4x2, but the sources given with it are 2x1 (resizing resamples them)");
  MaterialOptions resize = linear;
  resize.resize = true;
  auto resized = load_material(small, &schuler, pair, resize);
  ASSERT_TRUE(resized) << resized.error().to_string();
  EXPECT_EQ(resized->find("gloss")->width, 4);
  for (float v : resized->find("gloss")->pixels) EXPECT_NEAR(v, 0.2f, 1e-6);  // a constant image stays constant
}

}  // namespace
}  // namespace matbake::pack
