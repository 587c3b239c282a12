// KTX2 delivery end to end (`export --texture-format ktx2`, sizes, texel density) on a scene written
// here: each KTX2 file read back field by field and validated by basisu, the glTF checked by the
// Khronos validator, resizes in linear light against the closed form, the same bytes for any --jobs,
// and one error line for each bad setting. Tests that need basisu skip without it, saying so.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <thread>
#include <fstream>
#include <map>

#include "lib/src/gltf/document.hpp"
#include "matbake/color.hpp"
#include "matbake/ktx2.hpp"
#include "support/basisu.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A 1 × 1 quad (world area 1) mapped onto the whole UV square, drawn with material 0.
GltfBuilder quad_with_material_0() {
  GltfBuilder b;
  const int positions = b.add_vec3({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
  const int uvs = b.add_floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  const int normals = b.add_vec3({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1});
  const int tangents = b.add_floats({1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, "VEC4", 4);
  const int indices = b.add_indices({0, 1, 2, 0, 2, 3});
  b.doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}, {"NORMAL", normals},
                                                              {"TANGENT", tangents}}},
                                              {"indices", indices}, {"material", 0}}}}});
  b.add_node({{"mesh", 0}});
  return b;
}

// The quad drawn with one material that reads a colour texture with alpha (MASK, cutoff 0.5), an
// ORM texture and a normal map, each 32 × 32.
void write_textured_quad(const fs::path& dir, const std::string& alpha_mode = "MASK") {
  GltfBuilder b = quad_with_material_0();
  json material = {{"name", "leaves"},
                   {"alphaMode", alpha_mode},
                   {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 1}}}}},
                   {"normalTexture", {{"index", 2}}}};
  if (alpha_mode == "MASK") material["alphaCutoff"] = 0.5;
  b.doc["materials"] = {material};
  b.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33071}}};
  b.doc["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 1}}, {{"source", 2}}};
  b.doc["images"] = {{{"uri", "colour.png"}}, {{"uri", "orm.png"}}, {{"uri", "normal.png"}}};
  std::vector<double> colour, orm, normal;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      // Sparse leaves: one texel in four opaque (alpha 150 to 254), the rest nearly transparent.
      const double alpha = (x % 2 == 0 && y % 2 == 0) ? 150 + (x * 7 + y * 13) % 105 : (x * 5 + y * 3) % 40;
      colour.insert(colour.end(), {double(40 + 6 * x), double(120 + 3 * y), 60, alpha});
      orm.insert(orm.end(), {255, double(8 * y), double(8 * x)});
      const double nx = 0.3 * std::sin(0.4 * x), ny = 0.3 * std::cos(0.3 * y), nz = std::sqrt(1 - nx * nx - ny * ny);
      normal.insert(normal.end(), {std::round(127.5 + 127.5 * nx), std::round(127.5 + 127.5 * ny), std::round(127.5 + 127.5 * nz)});
    }
  }
  write_raw(dir / "colour.png", 32, 32, 4, "uint8", colour);
  write_raw(dir / "orm.png", 32, 32, 3, "uint8", orm);
  write_raw(dir / "normal.png", 32, 32, 3, "uint8", normal);
  b.write(dir / "quad.gltf", {0});
}

// The bytes of the image a texture shows: its KTX2 one, else its WebP one, else its core source.
std::vector<unsigned char> image_of(const gltf::Document& doc, int texture) {
  const json& t = doc.json["textures"][std::size_t(texture)];
  const json extensions = t.value("extensions", json::object());
  const int image = extensions.contains("KHR_texture_basisu") ? extensions["KHR_texture_basisu"]["source"].get<int>()
                    : extensions.contains("EXT_texture_webp") ? extensions["EXT_texture_webp"]["source"].get<int>()
                                                              : t["source"].get<int>();
  auto bytes = gltf::image_bytes(doc, std::size_t(image));
  EXPECT_TRUE(bytes);
  return {bytes->begin(), bytes->end()};
}

// The file of each texture a --json report lists, from the written scene.
std::vector<std::vector<unsigned char>> texture_files(const fs::path& scene, const json& textures) {
  const gltf::Document doc = read_output(scene);
  std::vector<std::vector<unsigned char>> files;
  for (const json& t : textures) files.push_back(image_of(doc, t["texture"]));
  return files;
}

json run_json(const std::vector<std::string>& args, const std::vector<std::string>& env) {
  std::vector<std::string> all = {"--json"};
  all.insert(all.end(), args.begin(), args.end());
  const RunResult r = matbake(all, env);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.exit_code == 0 ? json::parse(r.out) : json();
}

TEST(CliDelivery, KtxTexturesPerClassReadBackFieldByFieldAndValidate) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path());
  const fs::path out = dir / "out" / "quad.glb";
  const json report = run_json({"export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format", "ktx2"},
                               {"MATBAKE_BASISU=" + basisu});
  const gltf::Document doc = read_output(out);
  EXPECT_EQ(doc.json["extensionsUsed"], json::array({"KHR_texture_basisu"}));
  EXPECT_EQ(doc.json["extensionsRequired"], json::array({"KHR_texture_basisu"}));
  ASSERT_EQ(doc.json["images"].size(), 3u);  // the PNGs are gone
  struct Expected {
    std::uint8_t model, transfer;
    std::uint32_t supercompression;
  };
  const Expected expected[] = {{ktx2::kModelETC1S, ktx2::kTransferSRGB, ktx2::kSupercompressionBasisLZ},
                               {ktx2::kModelUASTC, ktx2::kTransferLinear, ktx2::kSupercompressionZstd},
                               {ktx2::kModelUASTC, ktx2::kTransferLinear, ktx2::kSupercompressionZstd}};
  for (int t = 0; t < 3; ++t) {
    SCOPED_TRACE(t);
    EXPECT_FALSE(doc.json["textures"][std::size_t(t)].contains("source"));
    const int image = doc.json["textures"][std::size_t(t)]["extensions"]["KHR_texture_basisu"]["source"];
    EXPECT_EQ(doc.json["images"][std::size_t(image)]["mimeType"], "image/ktx2");
    const std::vector<unsigned char> bytes = image_of(doc, t);
    auto k = ktx2::read(bytes, "texture");
    ASSERT_TRUE(k) << k.error().to_string();
    EXPECT_EQ(k->width, 32u);
    EXPECT_EQ(k->height, 32u);
    EXPECT_EQ(k->levels.size(), 6u);  // 32 … 1
    EXPECT_EQ(k->descriptor.model, expected[t].model);
    EXPECT_EQ(k->descriptor.transfer, expected[t].transfer);
    EXPECT_EQ(k->supercompression, expected[t].supercompression);
    if (expected[t].model == ktx2::kModelUASTC) {
      EXPECT_EQ(k->descriptor.channels, std::vector<std::uint8_t>{ktx2::kUastcRGB});
      for (std::size_t l = 0; l < 6; ++l) {
        const std::size_t side = std::max<std::size_t>(1, 32 >> l);
        auto data = ktx2::level_data(*k, l, "texture");
        ASSERT_TRUE(data) << data.error().to_string();
        EXPECT_EQ(data->size(), 16 * ((side + 3) / 4) * ((side + 3) / 4)) << l;
      }
    }
    write_bytes(dir / ("t" + std::to_string(t) + ".ktx2"), std::string(bytes.begin(), bytes.end()));
    const RunResult validated = run(basisu, {"-validate", "-file", (dir / ("t" + std::to_string(t) + ".ktx2")).string()});
    EXPECT_EQ(validated.exit_code, 0) << validated.out;
  }
  // The colour texture's coverage: 25% of the source's texels pass the cutoff, and every level made
  // keeps that within one texel's share (the ETC1S chain is basisu's: only level 0 is matbake's).
  const json& colour = report["textures"][0];
  EXPECT_EQ(colour["class"], "colour");
  EXPECT_EQ(colour["codec"], "etc1s");
  ASSERT_EQ(colour["coverage"].size(), 2u);
  EXPECT_DOUBLE_EQ(colour["coverage"][0].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(colour["coverage"][1].get<double>(), 0.25);
  // The validator knows no KHR_texture_basisu (KhronosGroup/glTF-Validator#177): exactly its two
  // warnings per KTX2 image, nothing else.
  MATBAKE_VALIDATE_OR_SKIP(validator, out);
  EXPECT_EQ(validator->errors, 0) << validator->summary;
  for (const std::string& code : validator->error_and_warning_codes) {
    EXPECT_TRUE(code.rfind("VALUE_NOT_IN_LIST /images/", 0) == 0 || code.rfind("IMAGE_UNRECOGNIZED_FORMAT /images/", 0) == 0)
        << code;
  }
  EXPECT_EQ(validator->warnings, 6) << validator->summary;
}

// KHR_texture_basisu: colour data BT.709 primaries and the sRGB transfer, non-colour data unspecified
// primaries and the linear transfer, whichever codec wrote it (basisu's ETC1S files say BT.709 for
// linear data and are corrected; matbake writes the UASTC descriptor itself).
TEST(CliDelivery, EveryCodecGivesDataTexturesNoPrimariesAndColourBt709) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path());
  for (const std::string codec : {"etc1s", "uastc"}) {
    SCOPED_TRACE(codec);
    const fs::path out = dir / (codec + ".glb");
    const RunResult r = matbake({"export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format", "ktx2",
                                 "--colour-codec", codec, "--data-codec", codec, "--normal-codec", codec},
                                {"MATBAKE_BASISU=" + basisu});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const gltf::Document doc = read_output(out);
    // Textures 0, 1, 2: base colour, metallic-roughness, normal.
    const std::uint8_t primaries[] = {1, 0, 0}, transfers[] = {2, 1, 1};
    for (int t = 0; t < 3; ++t) {
      const std::vector<unsigned char> bytes = image_of(doc, t);
      auto k = ktx2::read(bytes, "texture");
      ASSERT_TRUE(k) << k.error().to_string();
      EXPECT_EQ(k->descriptor.primaries, primaries[t]) << "texture " << t;
      EXPECT_EQ(k->descriptor.transfer, transfers[t]) << "texture " << t;
      const fs::path file = dir / (codec + std::to_string(t) + ".ktx2");
      write_bytes(file, std::string(bytes.begin(), bytes.end()));
      const RunResult validated = run(basisu, {"-validate", "-file", file.string()});
      EXPECT_EQ(validated.exit_code, 0) << validated.out;
    }
  }
}

// KHR_texture_basisu: "pixelWidth and pixelHeight MUST be multiples of 4": sides of 1, 2 and 3 (which
// rounds to 2) are raised to 4 (that they still look the same: Runtime.KhronosModels…, on
// TextureEncodingTest's 1 × 1 textures).
TEST(CliDelivery, TinyTexturesAreRaisedToFourTexelsInKtx2) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path(), "OPAQUE");
  write_raw(dir / "colour.png", 2, 1, 4, "uint8", {200, 100, 50, 255, 200, 100, 50, 255});
  write_raw(dir / "orm.png", 1, 1, 3, "uint8", {255, 128, 0});
  write_raw(dir / "normal.png", 3, 3, 3, "uint8", std::vector<double>(27, 128));
  json quad = json::parse(read_bytes(dir / "quad.gltf"));
  quad["textures"][0]["name"] = "ToyCar_clearcoat.png";  // a name the KTX2 texture must not keep
  // An embedded image without a name: named from the material and slot that read it.
  const std::string orm = read_bytes(dir / "orm.png");
  quad["images"][1] = {{"uri", "data:image/png;base64," + base64(std::vector<unsigned char>(orm.begin(), orm.end()))}};
  write_bytes(dir / "quad.gltf", quad.dump());
  const fs::path out = dir / "tiny.glb";
  const RunResult r = matbake({"export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format", "ktx2"},
                              {"MATBAKE_BASISU=" + basisu});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const gltf::Document doc = read_output(out);
  for (int t = 0; t < 3; ++t) {
    const std::vector<unsigned char> bytes = image_of(doc, t);
    auto k = ktx2::read(bytes, "texture");
    ASSERT_TRUE(k) << k.error().to_string();
    EXPECT_EQ(k->width, 4u) << "texture " << t;
    EXPECT_EQ(k->height, 4u) << "texture " << t;
    EXPECT_EQ(k->levels.size(), 3u) << "texture " << t;  // 4, 2, 1
    // Named as its KTX2 image is (from the file it replaced: colour, normal; the embedded one from its slot).
    const json& texture = doc.json["textures"][std::size_t(t)];
    const json& image = doc.json["images"][texture["extensions"]["KHR_texture_basisu"]["source"].get<std::size_t>()];
    EXPECT_EQ(texture["name"], image["name"]) << "texture " << t;
  }
  EXPECT_EQ(doc.json["images"][0]["name"], "colour");
  EXPECT_EQ(doc.json["images"][1]["name"], "leaves_metallicRoughness");
}

// --no-mipmaps: one level per KTX2 file, and samplers that do not ask for more: each texture's own
// sampler with LINEAR minification (wraps kept), one new sampler shared by the textures that had none.
TEST(CliDelivery, NoMipmapsGivesEachTextureASamplerWithoutMipmapFiltering) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path());
  const fs::path out = dir / "flat.gltf";
  const RunResult r = matbake({"export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format", "ktx2", "--no-mipmaps"},
                              {"MATBAKE_BASISU=" + basisu});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const gltf::Document doc = read_output(out);
  const json& textures = doc.json["textures"];
  const json& samplers = doc.json["samplers"];
  ASSERT_EQ(samplers.size(), 2u);  // the copy and the shared one (the quad's own, unused, is pruned)
  EXPECT_EQ(samplers[std::size_t(textures[0]["sampler"])], (json{{"wrapS", 33071}, {"wrapT", 33071}, {"minFilter", 9729}}));
  EXPECT_EQ(samplers[std::size_t(textures[1]["sampler"])], (json{{"minFilter", 9729}}));
  EXPECT_EQ(textures[1]["sampler"], textures[2]["sampler"]);
  for (int t = 0; t < 3; ++t) {
    auto k = ktx2::read(image_of(doc, t), "texture");
    ASSERT_TRUE(k) << k.error().to_string();
    EXPECT_EQ(k->levels.size(), 1u) << "texture " << t;
  }
  MATBAKE_VALIDATE_OR_SKIP(report, out);
  EXPECT_EQ(report->errors, 0) << report->summary;
  // README command 1's verdict on such a file: the two warnings per KTX2 image that the validator
  // raises only because it does not know KHR_texture_basisu, counted apart from any other.
  EXPECT_EQ(report->warnings, 6) << report->summary;
  const fs::path validate = fs::path(MATBAKE_SOURCE_DIR) / "scripts" / "gltf-validator" / "validate.js";
  const RunResult brief = run("/usr/bin/env", {"node", validate.string(), out.string(), "--brief"});
  EXPECT_EQ(brief.out, "0 errors, 0 warnings (and 6 on KTX2 images only because the validator does not know "
                       "KHR_texture_basisu yet, its issue #177)\n");
}

// Sparse leaves (a quarter of the texels opaque) keep their coverage at every level when asked; by
// default the levels are filtered as any texture's (gltfpack's and a runtime's own chain): level 1
// already renders next to nothing. Both reported per level.
TEST(CliDelivery, UastcColourKeepsCoverageWhenAskedAndJobsDoNotChangeBytes) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path());
  const std::vector<std::string> env = {"MATBAKE_BASISU=" + basisu};
  const json plain = run_json({"export", (dir / "quad.gltf").string(), "-o", (dir / "plain.glb").string(), "--texture-format", "ktx2",
                               "--colour-codec", "uastc"},
                              env);
  ASSERT_EQ(plain["textures"][0]["coverage"].size(), 7u);
  EXPECT_NEAR(plain["textures"][0]["coverage"][1].get<double>(), 0.25, 0.01);  // level 0 as the source
  EXPECT_LT(plain["textures"][0]["coverage"][2].get<double>(), 0.05);
  // ETC1S's levels are basisu's: asked to keep coverage there, the report says it cannot.
  const json etc1s = run_json({"export", (dir / "quad.gltf").string(), "-o", (dir / "etc1s.glb").string(), "--texture-format", "ktx2",
                               "--colour-codec", "etc1s", "--keep-alpha-coverage"},
                              env);
  EXPECT_NE(etc1s["textures"][0].value("note", "").find("keep_alpha_coverage does not act"), std::string::npos) << etc1s.dump();
  // Kaiser levels: box levels of this regular pattern hold runs of equal alphas, which no scale splits
  // (level 2 then keeps 18 of 64 texels, the nearest count its alphas allow).
  std::string first;
  for (const char* jobs : {"1", "2", "3"}) {
    const fs::path out = dir / jobs / "quad.glb";
    const json report = run_json({"--jobs", jobs, "export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format",
                                  "ktx2", "--colour-codec", "uastc", "--keep-alpha-coverage", "--mip-filter", "kaiser"},
                                 env);
    const json& coverage = report["textures"][0]["coverage"];
    ASSERT_EQ(coverage.size(), 7u);  // the source, then levels 0 … 5
    for (std::size_t l = 1; l < coverage.size(); ++l) {
      const double texels = std::pow(std::max(1.0, 32.0 / std::pow(2, double(l - 1))), 2);
      EXPECT_NEAR(coverage[l].get<double>(), 0.25, std::max(0.01, 0.5 / texels)) << "level " << l - 1;
    }
    const std::string bytes = read_bytes(out);
    if (first.empty()) first = bytes;
    EXPECT_EQ(bytes, first) << "--jobs " << jobs;
  }
}

// quad.gltf in `dir` whose material's baseColor is colour.png, width × height: ramps in red and
// green, a wave in blue (every block differs). Returns its samples, row by row.
std::vector<double> write_patterned_quad(const fs::path& dir, int width, int height) {
  GltfBuilder b = quad_with_material_0();
  b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.doc["textures"] = {{{"source", 0}}};
  b.doc["images"] = {{{"uri", "colour.png"}}};
  b.write(dir / "quad.gltf", {0});
  std::vector<double> colour;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      colour.insert(colour.end(), {std::round(255.0 * x / (width - 1)), std::round(255.0 * y / (height - 1)),
                                   std::round(127.5 + 100 * std::sin(0.05 * x) * std::cos(0.07 * y))});
    }
  }
  write_raw(dir / "colour.png", width, height, 3, "uint8", colour);
  return colour;
}

// An ETC1S run gets --jobs threads (one run at a time): basisu's threaded ETC1S must give the same
// bytes for any count, on a texture large enough for its threads to split (512², a pattern).
TEST(CliDelivery, Etc1sBytesDoNotDependOnJobs) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  const int side = 512;
  write_patterned_quad(dir.path(), side, side);
  const std::vector<std::string> env = {"MATBAKE_BASISU=" + basisu};
  std::string first;
  for (const char* jobs : {"1", "2", "3"}) {
    const fs::path out = dir / jobs / "quad.glb";
    const RunResult r = matbake({"--jobs", jobs, "export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format",
                                 "ktx2", "--colour-codec", "etc1s"},
                                env);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string bytes = read_bytes(out);
    if (first.empty()) first = bytes;
    EXPECT_EQ(bytes, first) << "--jobs " << jobs;
  }
}

// The patterned quad (64²) whose material reads colour.png twice, as base colour through a sampler
// wrapping (wrapS, wrapT) and as emissive through one wrapping (emissive_s, emissive_t).
void write_quad_reading_one_image_twice(const fs::path& dir, int wrap_s, int wrap_t, int emissive_s, int emissive_t) {
  fs::create_directories(dir);
  write_patterned_quad(dir, 64, 64);
  json quad = json::parse(read_bytes(dir / "quad.gltf"));
  quad["materials"][0]["emissiveTexture"] = {{"index", 1}};
  quad["materials"][0]["emissiveFactor"] = {1, 1, 1};
  quad["samplers"] = {{{"wrapS", wrap_s}, {"wrapT", wrap_t}}, {{"wrapS", emissive_s}, {"wrapT", emissive_t}}};
  quad["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 0}, {"sampler", 1}}};
  write_bytes(dir / "quad.gltf", quad.dump());
}

// One image under two samplers is one file, as gltfpack writes it, KTX2 or resized PNG: its chain is
// made once, its edges clamped on the axis where the samplers differ and wrapped as they agree on the
// other — byte for byte the file of the same image read through that sampler alone. The textures
// keep their own samplers, and their reports say why the edges are clamped.
TEST(CliDelivery, OneImageUnderTwoSamplersIsMadeOnceWithTheEdgesTheyAgreeOn) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  constexpr int kRepeat = 10497, kClamp = 33071, kMirror = 33648;
  const std::vector<std::string> env = {"MATBAKE_BASISU=" + basisu};
  const auto files = [](const fs::path& folder, const std::string& extension) {
    std::vector<std::string> out;
    for (const std::string& f : list_folder(folder)) {
      if (f.ends_with(extension)) out.push_back(f);
    }
    return out;
  };
  for (const std::vector<std::string>& format :
       {std::vector<std::string>{"--texture-format", "ktx2"}, std::vector<std::string>{"--colour-max-size", "32"}}) {
    const std::string extension = format[0] == "--texture-format" ? ".ktx2" : ".png";
    TempDir dir;
    write_quad_reading_one_image_twice(dir / "shared", kRepeat, kMirror, kRepeat, kClamp);
    write_quad_reading_one_image_twice(dir / "alone", kRepeat, kClamp, kRepeat, kClamp);
    std::vector<std::string> args = {"export", (dir / "shared" / "quad.gltf").string(), "-o", (dir / "shared" / "out" / "quad.gltf").string()};
    args.insert(args.end(), format.begin(), format.end());
    const json report = run_json(args, env);
    args[1] = (dir / "alone" / "quad.gltf").string();
    args[3] = (dir / "alone" / "out" / "quad.gltf").string();
    run_json(args, env);

    const std::vector<std::string> shared = files(dir / "shared" / "out", extension), alone = files(dir / "alone" / "out", extension);
    ASSERT_EQ(shared.size(), 1u) << extension;
    ASSERT_EQ(alone.size(), 1u) << extension;
    EXPECT_EQ(read_bytes(dir / "shared" / "out" / shared[0]), read_bytes(dir / "alone" / "out" / alone[0])) << extension;
    const gltf::Document doc = read_output(dir / "shared" / "out" / "quad.gltf");
    ASSERT_EQ(doc.json["textures"].size(), 2u);
    EXPECT_NE(doc.json["textures"][0]["sampler"], doc.json["textures"][1]["sampler"]);
    EXPECT_EQ(doc.json["images"].size(), 1u);
    const json& textures = report["textures"];
    ASSERT_EQ(textures.size(), 2u) << report.dump();
    for (const json& t : textures) EXPECT_NE(t.value("note", "").find("clamp to edge"), std::string::npos) << t.dump();
    MATBAKE_VALIDATE_OR_SKIP(validated, dir / "shared" / "out" / "quad.gltf");
    EXPECT_EQ(validated->errors, 0) << validated->summary;
  }
}

// Level 0 of a 1024 × 1088 UASTC texture is larger than one encoder run's strip (65 536 blocks): it is
// encoded in two strips in parallel, RDO on. The bytes are the same for any --jobs, and the strips
// land where they belong: level 0 transcoded (basisu -unpack, BC7) is within UASTC's error of the
// source in every band of 64 rows (a strip out of place or order misses by tens of codes).
TEST(CliDelivery, LargeLevelsEncodeInStripsInPlaceWithBytesIndependentOfJobs) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  const int width = 1024, height = 1088;
  const std::vector<double> colour = write_patterned_quad(dir.path(), width, height);
  const std::vector<std::string> env = {"MATBAKE_BASISU=" + basisu};
  std::string first;
  for (const char* jobs : {"1", "2", "3"}) {
    const fs::path out = dir / jobs / "quad.gltf";
    const json report = run_json({"--jobs", jobs, "export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format",
                                  "ktx2", "--colour-codec", "uastc", "--colour-uastc-level", "0", "--colour-uastc-rdo", "1",
                                  "--no-mipmaps"},
                                 env);
    ASSERT_EQ(report["textures"].size(), 1u);
    const std::string bytes = read_bytes(out.parent_path() / report["textures"][0]["file"].get<std::string>());
    if (first.empty()) first = bytes;
    EXPECT_EQ(bytes, first) << "--jobs " << jobs;
  }
  const fs::path ktx2 = dir / "1" / "level0.ktx2";
  write_bytes(ktx2, first);
  const RunResult unpacked = run("/usr/bin/env", {"-C", (dir / "1").string(), basisu, "-unpack", "-no_ktx", "-format_only", "6", "level0.ktx2"});
  ASSERT_EQ(unpacked.exit_code, 0) << unpacked.err;
  const RawImage decoded = read_raw(dir / "1" / "level0_unpacked_rgb_BC7_RGBA_0_0000.png");
  ASSERT_EQ(decoded.width, width);
  ASSERT_EQ(decoded.height, height);
  for (int band = 0; band < height / 64; ++band) {
    double squared = 0;
    for (int y = band * 64; y < band * 64 + 64; ++y) {
      for (int x = 0; x < width; ++x) {
        for (int c = 0; c < 3; ++c) {
          const std::size_t in = (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3 + std::size_t(c);
          const std::size_t out = (std::size_t(y) * std::size_t(width) + std::size_t(x)) * std::size_t(decoded.channels) + std::size_t(c);
          squared += std::pow(decoded.samples[out] - colour[in], 2);
        }
      }
    }
    EXPECT_LT(std::sqrt(squared / (64.0 * width * 3)), 3.0) << "rows " << band * 64 << "–" << band * 64 + 63;
  }
}

// The example twice in one build, both delivering `format` (a manifest's lines) with AO into their
// ORM textures at 64 texels: every made texture is encoded by one of the two scenes and read from the
// encode cache by the other (same bytes). Then the twin's AO changes: it rebuilds, the showroom does
// not, and exactly the twin's textures whose bytes changed (its ORM textures) are encoded again.
// Returns the twin's textures as last built.
json expect_each_texture_encoded_once(const fs::path& dir, const std::string& format, const std::vector<std::string>& env) {
  copy_example(dir);
  std::string manifest = read_bytes(dir / "showroom.toml");
  const std::string ao = "samples = 128, relative_distance = 0.25, texture = 256";
  manifest.replace(manifest.find(ao), ao.size(), "samples = 8, relative_distance = 0.25, texture = 64");
  manifest += format + "\n[scenes.twin]\ninput = \"showroom.gltf\"\noutput = \"twin.glb\"\n" + format +
              "ao = { samples = 8, relative_distance = 0.25, texture = 64, per_instance = true }\n";
  write_bytes(dir / "showroom.toml", manifest);
  const auto build = [&] {
    std::map<std::string, json> scenes;
    const json report = run_json({"build", (dir / "showroom.toml").string()}, env);
    for (const json& job : report["jobs"]) {  // an up-to-date job has no details
      const json details = job.value("details", json::object());
      if (details.contains("textures")) scenes[job["name"]] = details["textures"];
    }
    return scenes;
  };
  std::map<std::string, json> first = build();
  EXPECT_EQ(first.size(), 2u);
  const json &showroom = first["scene:showroom"], &twin = first["scene:twin"];
  EXPECT_EQ(showroom.size(), twin.size());
  EXPECT_GE(showroom.size(), 10u);
  const auto showroom_bytes = texture_files(dir / "out" / "showroom.glb", showroom), twin_bytes = texture_files(dir / "out" / "twin.glb", twin);
  for (std::size_t i = 0; i < std::min(showroom.size(), twin.size()); ++i) {
    EXPECT_NE(showroom[i]["reused"].get<bool>(), twin[i]["reused"].get<bool>()) << "texture " << i << ": encoded once";
    EXPECT_EQ(showroom_bytes[i], twin_bytes[i]) << "texture " << i;
    EXPECT_GT(twin_bytes[i].size(), 60u) << "texture " << i;
  }

  manifest.replace(manifest.rfind("samples = 8"), 11, "samples = 16");
  write_bytes(dir / "showroom.toml", manifest);
  std::map<std::string, json> second = build();
  EXPECT_EQ(second.size(), 1u) << "the showroom is up to date";
  const json& rebuilt = second["scene:twin"];
  const auto rebuilt_bytes = texture_files(dir / "out" / "twin.glb", rebuilt);
  int encoded = 0;
  for (std::size_t i = 0; i < std::min(rebuilt.size(), twin_bytes.size()); ++i) {
    const bool reused = rebuilt[i]["reused"];
    EXPECT_EQ(reused, rebuilt_bytes[i] == twin_bytes[i]) << rebuilt[i]["file"];
    EXPECT_EQ(reused, rebuilt[i]["file"].get<std::string>().find("_orm_") == std::string::npos) << rebuilt[i]["file"];
    encoded += reused ? 0 : 1;
  }
  EXPECT_GT(encoded, 0);
  EXPECT_LT(encoded, int(rebuilt.size()));
  return rebuilt;
}

TEST(CliDelivery, TheEncodeCacheEncodesEachKtx2TextureOnceAndAnAoChangeOnlyWhatItChanged) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  const std::vector<std::string> env = {"MATBAKE_BASISU=" + basisu};
  const json rebuilt =
      expect_each_texture_encoded_once(dir.path(), "texture_format = \"ktx2\"\ncolour_max_size = 64\ndata_max_size = 64\n", env);
  // A damaged entry is encoded again, to the same bytes.
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "out" / ".matbake" / "encode-cache")) {
    fs::resize_file(e.path(), fs::file_size(e.path()) / 2);  // every entry damaged
  }
  const RunResult forced = matbake({"--json", "build", (dir / "showroom.toml").string(), "--force", "--only", "scene:twin"}, env);
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_NE(forced.err.find(" scene:twin built ("), std::string::npos) << forced.err;
  EXPECT_NE(forced.err.find(" ms, textures: " + std::to_string(rebuilt.size()) + " encoded, 0 from the encode cache)"), std::string::npos)
      << forced.err;
  const json forced_report = json::parse(forced.out);  // named: a range over a temporary's member dangles
  for (const json& job : forced_report["jobs"]) {
    const json textures = job.value("details", json::object()).value("textures", json::array());
    for (const json& t : textures) EXPECT_FALSE(t["reused"].get<bool>()) << t["file"];
  }
  EXPECT_EQ(texture_files(dir / "out" / "twin.glb", rebuilt), texture_files(dir / "out" / "twin.glb", forced_report["jobs"][0]["details"]["textures"]));

  std::vector<std::string> bad_env = env;
  bad_env.push_back("MATBAKE_ENCODE_CACHE_MB=lots");
  const RunResult bad = matbake({"build", (dir / "showroom.toml").string(), "--force"}, bad_env);
  EXPECT_EQ(bad.exit_code, 2);
  expect_one_error_line(bad, "MATBAKE_ENCODE_CACHE_MB", "'lots': a whole number of MiB (0 turns the encode cache off)");
}

// The same for the PNG files of resized textures (WebP entries: EncodeCache.PngAndWebpEntries…).
TEST(CliDelivery, TheEncodeCacheKeepsResizedPngTextures) {
  TempDir dir;
  expect_each_texture_encoded_once(dir.path(), "texture_format = \"png\"\ncolour_max_size = 64\ndata_max_size = 64\nnormal_max_size = 64\n", {});
}

TEST(CliDelivery, PngFallbackKeepsTheSourceAndTheExtensionIsOnlyUsed) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path(), "OPAQUE");
  const fs::path out = dir / "out" / "quad.gltf";
  run_json({"export", (dir / "quad.gltf").string(), "-o", out.string(), "--texture-format", "ktx2", "--png-fallback",
            "--normal-codec", "png"},
           {"MATBAKE_BASISU=" + basisu});
  const gltf::Document doc = read_output(out);
  EXPECT_EQ(doc.json["extensionsUsed"], json::array({"KHR_texture_basisu"}));
  EXPECT_FALSE(doc.json.contains("extensionsRequired"));
  for (int t = 0; t < 2; ++t) {
    EXPECT_TRUE(doc.json["textures"][std::size_t(t)].contains("source"));
    EXPECT_TRUE(doc.json["textures"][std::size_t(t)]["extensions"].contains("KHR_texture_basisu"));
  }
  EXPECT_EQ(doc.json["textures"][2], (json{{"source", 2}}));  // the normal map kept as PNG
  EXPECT_TRUE(fs::exists(dir / "out" / "colour.ktx2"));
  EXPECT_TRUE(fs::exists(dir / "out" / "orm.ktx2"));
  EXPECT_FALSE(fs::exists(dir / "out" / "normal.ktx2"));
}

// A checkerboard of sRGB codes 0 and 255 halved: its linear mean is 0.5, which sRGB stores as code
// 188. Filtering the codes themselves (gamma space) would give 128. (The texture's sampler clamps:
// within 3 texels of an edge the Kaiser window reads the edge texel again, so only the interior is
// exact there.)
TEST(CliDelivery, ResizesAreInLinearLightAndNeverAboveTheSource) {
  TempDir dir;
  write_textured_quad(dir.path(), "OPAQUE");
  std::vector<double> checker;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      const double v = (x + y) % 2 ? 255 : 0;
      checker.insert(checker.end(), {v, v, v, 255});
    }
  }
  write_raw(dir / "colour.png", 32, 32, 4, "uint8", checker);
  const fs::path out = dir / "out" / "quad.gltf";
  const json report = run_json({"export", (dir / "quad.gltf").string(), "-o", out.string(), "--colour-max-size", "16",
                                "--data-max-size", "64", "--normal-scale", "0.25"},
                               {});
  const gltf::Document doc = read_output(out);
  const int image = doc.json["textures"][0]["source"];
  const std::string uri = doc.json["images"][std::size_t(image)]["uri"];
  EXPECT_EQ(uri, "colour_16x16.png");
  const RawImage half = read_raw(dir / "out" / uri);
  ASSERT_EQ(half.width, 16);
  const double expected = std::round(255 * color::encoded_from_linear(color::Transfer::srgb, 0.5));
  EXPECT_EQ(expected, 188);
  for (int y = 3; y < 13; ++y) {
    for (int x = 3; x < 13; ++x) {
      for (int c = 0; c < 4; ++c) EXPECT_EQ(half.samples[std::size_t((y * 16 + x) * 4 + c)], c == 3 ? 255 : expected) << x << " " << y;
    }
  }
  // --data-max-size 64 is above the source: the ORM texture is kept as it was.
  EXPECT_EQ(report["textures"][1]["size"], json::array({32, 32}));
  EXPECT_EQ(report["textures"][1]["file"], "");
  EXPECT_EQ(report["textures"][2]["size"], json::array({8, 8}));
  EXPECT_EQ(doc.json["images"].size(), 3u);  // the replaced PNGs are not written
  EXPECT_FALSE(fs::exists(dir / "out" / "colour.png"));
}

// The quad has world area 1 over the whole UV square: 8 texels per unit need an 8 × 8 texture.
TEST(CliDelivery, TexelDensitySizesTexturesFromTheScene) {
  TempDir dir;
  write_textured_quad(dir.path(), "OPAQUE");
  const json report = run_json({"export", (dir / "quad.gltf").string(), "-o", (dir / "out" / "quad.glb").string(),
                                "--texel-density", "8"},
                               {});
  for (const json& t : report["textures"]) {
    EXPECT_EQ(t["needed_side"], 8) << t;
    EXPECT_EQ(t["size"], json::array({8, 8})) << t;
    EXPECT_EQ(t["materials"], json::array({0})) << t;
    EXPECT_LT(t["bytes"].get<int>(), t["source_bytes"].get<int>()) << t;
  }
}

// KHR_texture_transform scales the UV area a texture is read over: tiled 3× (scale 3) the quad
// needs 8 / 3 texels per texture side, at scale 0.5 twice 8, at scale (1, 2) rotated 8 / √2; each
// texture of the one material gets its own size (they all got 8).
TEST(CliDelivery, TexelDensityFollowsEachTexturesTransform) {
  TempDir dir;
  write_textured_quad(dir.path(), "OPAQUE");
  json doc = json::parse(read_bytes(dir / "quad.gltf"));
  json& material = doc["materials"][0];
  const auto transform = [](json scale, double rotation) {
    return json{{"KHR_texture_transform", {{"scale", scale}, {"rotation", rotation}}}};
  };
  material["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = transform({3, 3}, 0);
  material["pbrMetallicRoughness"]["metallicRoughnessTexture"]["extensions"] = transform({1, 2}, 0.7);
  material["normalTexture"]["extensions"] = transform({0.5, 0.5}, 0);
  doc["extensionsUsed"] = {"KHR_texture_transform"};
  write_bytes(dir / "quad.gltf", doc.dump());
  const json report = run_json({"export", (dir / "quad.gltf").string(), "-o", (dir / "out" / "quad.glb").string(),
                                "--texel-density", "8"},
                               {});
  ASSERT_EQ(report["textures"].size(), 3u);
  EXPECT_EQ(report["textures"][0]["needed_side"], 3);   // ceil(8 / 3)
  EXPECT_EQ(report["textures"][1]["needed_side"], 6);   // ceil(8 / √2)
  EXPECT_EQ(report["textures"][2]["needed_side"], 16);  // 8 / 0.5
  // Rounded to the nearest power of two in ratio (3 → 4, 6 → 8).
  EXPECT_EQ(report["textures"][0]["size"], json::array({4, 4}));
  EXPECT_EQ(report["textures"][1]["size"], json::array({8, 8}));
  EXPECT_EQ(report["textures"][2]["size"], json::array({16, 16}));
}

// README command 1's KTX2 variant: the example's scene, built, then exported with KTX2 textures.
TEST(CliDelivery, TheExampleSceneAsKtx2HasNoValidatorErrors) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  copy_example(dir.path(), true);
  ASSERT_EQ(matbake({"build", (dir / "showroom.toml").string(), "--quiet"}).exit_code, 0);
  const fs::path out = dir / "out" / "showroom-ktx2.glb";
  const json report = run_json({"export", (dir / "out" / "showroom.glb").string(), "-o", out.string(), "--texture-format", "ktx2"},
                               {"MATBAKE_BASISU=" + basisu});
  std::size_t ktx2_images = 0;
  for (const json& t : report["textures"]) {
    ktx2_images += t["codec"] != "png";
    EXPECT_TRUE(t["codec"] == "etc1s" || t["codec"] == "uastc") << t;
  }
  EXPECT_EQ(ktx2_images, 15u);  // 5 base colours, 10 ORM textures (one per placement, AO baked in)
  MATBAKE_VALIDATE_OR_SKIP(validator, out);
  EXPECT_EQ(validator->errors, 0) << validator->summary;
  EXPECT_EQ(validator->warnings, int(2 * ktx2_images)) << validator->summary;
}

// A build's scene stamps every delivery setting and the encoder's version: a change to either
// rebuilds the scene, and nothing else does.
TEST(CliDelivery, TheStampHoldsEverySettingAndTheEncodersVersion) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path());
  const std::string manifest = (dir / "assets.toml").string();
  std::ofstream(manifest) << "[scenes.s]\ninput = \"quad.gltf\"\ntexture_format = \"ktx2\"\n";
  const std::vector<std::string> env = {"MATBAKE_BASISU=" + basisu};
  ASSERT_EQ(run_json({"build", manifest}, env)["built"], 1);
  EXPECT_EQ(run_json({"build", manifest, "--dry-run"}, env)["out_of_date"], 0);
  // Another basisu version (a wrapper that says so) makes the scene out of date.
  const fs::path wrapper = dir / "basisu-next";
  std::ofstream(wrapper) << "#!/bin/sh\nif [ \"$1\" = -version ]; then echo 'Basis Universal GPU Texture Compressor v1.16.5'; "
                            "else exec '" << basisu << "' \"$@\"; fi\n";
  fs::permissions(wrapper, fs::perms::owner_all);
  const json other = run_json({"build", manifest, "--dry-run"}, {"MATBAKE_BASISU=" + wrapper.string()});
  EXPECT_EQ(other["out_of_date"], 1) << other.dump();
  EXPECT_EQ(other["jobs"][0]["changed"][0]["parameter"], "encoder") << other.dump();
  // No basisu at all: said as such, not as a changed option.
  const json missing = run_json({"build", manifest, "--dry-run"}, {"MATBAKE_BASISU=" + (dir / "no-basisu").string()});
  EXPECT_EQ(missing["jobs"][0]["reason"].get<std::string>().rfind("basisu is missing: ", 0), 0u) << missing.dump();
  std::ofstream(manifest, std::ios::app) << "colour_quality = 200\n";
  const json changed = run_json({"build", manifest, "--dry-run"}, env);
  EXPECT_EQ(changed["jobs"][0]["reason"], "its options changed: export.colour_quality 128 → 200") << changed.dump();
}

// bake-ao's door: the occlusion textures it bakes, and every other texture, delivered as KTX2.
TEST(CliDelivery, BakeAoWritesItsTexturesAsKtx2) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path(), "OPAQUE");
  const fs::path out = dir / "out" / "baked.glb";
  const json report = run_json({"bake-ao", (dir / "quad.gltf").string(), "-o", out.string(), "--texture", "16", "--samples", "4",
                                "--texture-format", "ktx2", "--data-uastc-level", "0"},
                               {"MATBAKE_BASISU=" + basisu});
  ASSERT_EQ(report["delivered"].size(), 4u);  // colour, ORM, normal, and the baked occlusion
  for (const json& t : report["delivered"]) EXPECT_NE(t["codec"], "png") << t;
  const gltf::Document doc = read_output(out);
  EXPECT_EQ(doc.json["extensionsRequired"], json::array({"KHR_texture_basisu"}));
  for (const auto& image : doc.json["images"]) EXPECT_EQ(image["mimeType"], "image/ktx2");
}

TEST(CliDelivery, BadSettingsAndAMissingEncoderAreOneErrorLineAndNothingIsWritten) {
  TempDir dir;
  write_textured_quad(dir.path());
  const std::string in = (dir / "quad.gltf").string(), out = (dir / "out" / "quad.glb").string();
  const RunResult missing = matbake({"export", in, "-o", out, "--texture-format", "ktx2"}, {"MATBAKE_BASISU=/nonexistent/basisu"});
  EXPECT_EQ(missing.exit_code, 1);
  expect_one_error_line(missing, "/nonexistent/basisu", "the KTX2 encoder (MATBAKE_BASISU) does not run as basisu");
  EXPECT_NE(missing.err.find("scripts/install-basisu.sh"), std::string::npos);
  const RunResult none = matbake({"export", in, "-o", out, "--texture-format", "ktx2"}, {"MATBAKE_BASISU=", "PATH=/nonexistent"});
  EXPECT_EQ(none.exit_code, 1);
  expect_one_error_line(none, "", "the KTX2 encoder basisu is not on PATH");
  const RunResult failing = matbake({"export", in, "-o", out, "--texture-format", "ktx2"}, {"MATBAKE_BASISU=/bin/false"});
  EXPECT_EQ(failing.exit_code, 1);
  EXPECT_EQ(std::count(failing.err.begin(), failing.err.end(), '\n'), 1) << failing.err;
  for (const auto& args : std::vector<std::vector<std::string>>{{"--colour-max-size", "0"},
                                                                {"--normal-max-size", "16385"},
                                                                {"--data-codec", "astc"},
                                                                {"--colr-codec", "uastc"},
                                                                {"--colour-scale", "0"},
                                                                {"--texture-format", "ktx"}}) {
    std::vector<std::string> all = {"export", in, "-o", out};
    all.insert(all.end(), args.begin(), args.end());
    const RunResult r = matbake(all);
    EXPECT_EQ(r.exit_code, 2) << args[0] << " " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(args[0]), std::string::npos) << r.err;
  }
  // No rounding: a 30-texel side cannot be KTX2 (sides must be multiples of 4).
  MATBAKE_BASISU_OR_SKIP(basisu);
  const RunResult odd = matbake({"export", in, "-o", out, "--texture-format", "ktx2", "--texture-rounding", "none",
                                 "--colour-max-size", "30"},
                                {"MATBAKE_BASISU=" + basisu});
  EXPECT_EQ(odd.exit_code, 2) << odd.err;
  expect_one_error_line(odd, in, "texture 0 (colour) would be 30x30: KTX2 (KHR_texture_basisu) needs sides that are multiples of 4; "
                                 "use --texture-rounding multiple-of-4 or power-of-two");
  EXPECT_TRUE(!fs::exists(dir / "out") || list_folder(dir / "out").empty());
  // The same library error in a build speaks the manifest's words.
  std::ofstream(dir / "assets.toml") << "[scenes.s]\ninput = \"quad.gltf\"\ntexture_format = \"ktx2\"\ntexture_rounding = \"none\"\n"
                                        "colour_max_size = 30\n";
  const RunResult keys = matbake({"build", (dir / "assets.toml").string()}, {"MATBAKE_BASISU=" + basisu});
  EXPECT_EQ(keys.exit_code, 1) << keys.err;
  EXPECT_NE(keys.err.find("; use texture_rounding = \"multiple-of-4\" or power-of-two (scene:s)"), std::string::npos) << keys.err;
  // The manifest's door: the same checks at the key's line and column.
  std::ofstream(dir / "assets.toml") << "[scenes.s]\ninput = \"quad.gltf\"\ntexture_format = \"ktx2\"\ncolour_max_size = 0\n";
  const RunResult manifest = matbake({"build", (dir / "assets.toml").string(), "-n"});
  EXPECT_EQ(manifest.exit_code, 1) << manifest.err;
  EXPECT_NE(manifest.err.find("assets.toml:4:19"), std::string::npos) << manifest.err;
  std::ofstream(dir / "assets.toml") << "[scenes.s]\ninput = \"quad.gltf\"\ncolor_codec = \"uastc\"\n";
  const RunResult unknown = matbake({"build", (dir / "assets.toml").string(), "-n"});
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.err.find("colour_codec"), std::string::npos) << unknown.err;
}

// A stand-in encoder that answers -version as basisu does, then misbehaves as MODE says: hang
// (ignoring SIGTERM, SIGINT and SIGHUP), flood (50 MB of output, then an error), huge (a 1 GB output
// file). HANG_VERSION=1 makes -version hang. It writes its process id to PIDFILE.
fs::path misbehaving_encoder(const fs::path& dir) {
  const fs::path script = dir / "basisu";
  write_bytes(script, "#!/bin/bash\n"
                      "if [ \"$1\" = -version ]; then\n"
                      "  [ -n \"$HANG_VERSION\" ] && exec sleep 1000\n"
                      "  echo 'Basis Universal GPU Texture Compressor v1.16.4'; exit 0\n"
                      "fi\n"
                      "echo $$ > \"$PIDFILE\"\n"
                      "trap '' TERM INT HUP\n"
                      "case $MODE in\n"
                      "  hang) while :; do sleep 1; done ;;\n"
                      "  flood) head -c 50000000 /dev/zero | tr '\\0' x; echo; echo 'ERROR: flooded'; exit 1 ;;\n"
                      "  huge) while [ $# -gt 0 ]; do [ \"$1\" = -output_path ] && { out=$2; shift; }; last=$1; shift; done\n"
                      "        truncate -s 1G \"$out/$(basename \"$last\" .png).ktx2\" ;;\n"
                      "esac\n");
  fs::permissions(script, fs::perms::owner_exec, fs::perm_options::add);
  return script;
}

// Whether process `pid` still runs (a zombie does not).
bool still_runs(const std::string& pid) {
  const std::string stat = fs::exists("/proc/" + pid + "/stat") ? read_bytes("/proc/" + pid + "/stat") : "";
  const std::size_t paren = stat.rfind(')');
  return paren != std::string::npos && stat.size() > paren + 2 && stat[paren + 2] != 'Z' && stat[paren + 2] != 'X';
}

// The encoder is supervised: a hung -version or encode is killed at its time limit, a flood of
// output costs its last lines, a 1 GB output is refused by its size before it is read.
TEST(CliDelivery, TheEncoderIsSupervised) {
  TempDir dir;
  write_textured_quad(dir.path());
  const fs::path encoder = misbehaving_encoder(dir.path());
  const std::string in = (dir / "quad.gltf").string(), out = (dir / "out" / "quad.glb").string(), pidfile = (dir / "pid").string();
  const std::vector<std::string> args = {"export", in, "-o", out, "--texture-format", "ktx2"};
  const std::vector<std::string> base = {"MATBAKE_BASISU=" + encoder.string(), "PIDFILE=" + pidfile, "MATBAKE_ENCODER_TIME_LIMIT=1"};
  const auto with = [&](const std::string& setting) {
    std::vector<std::string> env = base;
    env.push_back(setting);
    return env;
  };
  const RunResult probe = matbake(args, with("HANG_VERSION=1"));
  EXPECT_EQ(probe.exit_code, 1);
  expect_one_error_line(probe, encoder.string(), "the KTX2 encoder (MATBAKE_BASISU) does not run as basisu: it did not answer -version within 1 s");
  const RunResult hang = matbake(args, with("MODE=hang"));
  EXPECT_EQ(hang.exit_code, 1);
  EXPECT_NE(hang.err.find("did not finish within its time limit of 1 s (killed"), std::string::npos) << hang.err;
  EXPECT_FALSE(still_runs(read_bytes(pidfile).substr(0, read_bytes(pidfile).find('\n'))));
  const RunResult flood = matbake(args, with("MODE=flood"));
  EXPECT_EQ(flood.exit_code, 1);
  EXPECT_EQ(std::count(flood.err.begin(), flood.err.end(), '\n'), 1) << flood.err.size();
  EXPECT_NE(flood.err.find("failed (exit 1): ERROR: flooded"), std::string::npos) << flood.err.substr(0, 500);
  const RunResult huge = matbake(args, with("MODE=huge"));
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_NE(huge.err.find("the encoder wrote 1073741824 bytes, more than the"), std::string::npos) << huge.err;
  EXPECT_TRUE(!fs::exists(dir / "out") || list_folder(dir / "out").empty());
}

// SIGTERM to matbake while the encoder runs (and ignores SIGTERM itself): matbake exits at once
// and takes the encoder's whole group with it; nothing keeps its stderr open.
TEST(CliDelivery, AnInterruptKillsTheEncoder) {
  TempDir dir;
  write_textured_quad(dir.path());
  const fs::path encoder = misbehaving_encoder(dir.path());
  const std::string pidfile = (dir / "pid").string();
  // matbake's output through a pipe (as `matbake ... | tee` has it): the reader ends only when
  // every writer, the encoder included, has closed it.
  const std::string command = "(MATBAKE_BASISU='" + encoder.string() + "' PIDFILE='" + pidfile + "' MODE=hang '" + matbake_exe() +
                              "' export '" + (dir / "quad.gltf").string() + "' -o '" + (dir / "out/q.glb").string() +
                              "' --texture-format ktx2 2>&1 & echo $! > '" + (dir / "mpid").string() + "'; wait) | cat & reader=$!; "
                              "for i in $(seq 100); do [ -s '" + pidfile + "' ] && break; sleep 0.1; done; "
                              "kill -TERM $(cat '" + (dir / "mpid").string() + "'); "
                              "{ sleep 15; kill -9 $reader; } >/dev/null 2>&1 & dog=$!; wait $reader; kill $dog";
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run("/bin/bash", {"-c", command});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);  // not the 15 s timeout
  EXPECT_NE(r.out.find("matbake: interrupted"), std::string::npos) << r.out << r.err;
  ASSERT_TRUE(fs::exists(pidfile));
  const std::string pid = read_bytes(pidfile).substr(0, read_bytes(pidfile).find('\n'));
  for (int i = 0; i < 50 && still_runs(pid); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(still_runs(pid)) << pid;
}

// kill -9 of matbake mid-encode: the encoder dies with it (PR_SET_PDEATHSIG), and the scratch it
// leaves in the output's folder is removed by the next run there (its owner is provably gone).
TEST(CliDelivery, KillNineMidEncodeLeavesNothingRunningAndTheNextRunSweeps) {
  TempDir dir;
  write_textured_quad(dir.path());
  const fs::path encoder = misbehaving_encoder(dir.path());
  const std::string pidfile = (dir / "pid").string(), out = (dir / "out/q.glb").string();
  const std::string command = "MATBAKE_BASISU='" + encoder.string() + "' PIDFILE='" + pidfile + "' MODE=hang '" + matbake_exe() +
                              "' export '" + (dir / "quad.gltf").string() + "' -o '" + out + "' --texture-format ktx2 "
                              ">/dev/null 2>&1 & m=$!; for i in $(seq 100); do [ -s '" + pidfile + "' ] && break; sleep 0.1; done; "
                              "kill -KILL $m; wait $m; echo $?";
  const RunResult r = run("/bin/bash", {"-c", command});
  EXPECT_EQ(r.out, "137\n") << r.err;
  const std::string pid = read_bytes(pidfile).substr(0, read_bytes(pidfile).find('\n'));
  for (int i = 0; i < 100 && still_runs(pid); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(still_runs(pid)) << pid;
  const auto leftovers = [&] {
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(dir / "out")) {
      if (e.path().filename().string().rfind(".matbake-tmp-", 0) == 0) found.push_back(e.path().string());
    }
    return found;
  };
  ASSERT_EQ(leftovers().size(), 1u);  // the killed run's scratch
  EXPECT_EQ(matbake({"export", (dir / "quad.gltf").string(), "-o", out}).exit_code, 0);
  EXPECT_EQ(leftovers(), std::vector<std::string>{});
}

// An ETC1S file of another size or level count than asked for is refused, not delivered.
TEST(CliDelivery, AnEncoderOutputOfTheWrongSizeIsRefused) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  write_textured_quad(dir.path());
  for (const std::string& extra : {std::string("-resample 8 8"), std::string("-mip_smallest 8")}) {
    const fs::path wrapper = dir / "basisu-wrong";
    write_bytes(wrapper, "#!/bin/bash\ncase \" $* \" in *\" -uastc \"*|*\" -version \"*) exec '" + basisu + "' \"$@\" ;; esac\n"
                         "exec '" + basisu + "' \"$@\" " + extra + "\n");
    fs::permissions(wrapper, fs::perms::owner_exec, fs::perm_options::add);
    const RunResult r = matbake({"export", (dir / "quad.gltf").string(), "-o", (dir / "out/q.glb").string(), "--texture-format", "ktx2"},
                                {"MATBAKE_BASISU=" + wrapper.string()});
    EXPECT_EQ(r.exit_code, 1) << extra;
    EXPECT_NE(r.err.find("wrote an unexpected KTX2 file"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("asked for ETC1S 32x32, 6 levels"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out/q.glb"));
  }
}

}  // namespace
}  // namespace matbake::test
