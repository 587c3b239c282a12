// `matbake bake-ao` end to end: a wall on a floor through the CLI, byte-identical dumps across
// thread counts, and bad scenes refused with nothing written.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "lib/src/gltf/document.hpp"
#include "matbake/image.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

// A 2000-unit floor as a fan around the origin (vertex 0), and a wall just behind x = 0 facing +x.
void write_wall_scene(const fs::path& path) {
  GltfBuilder b;
  const float h = 1000, gap = 1e-3f;
  const int floor = b.add_mesh(b.add_vec3({0, 0, 0, -h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0}),
                               b.add_indices({0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1}));
  const int wall = b.add_mesh(b.add_vec3({-gap, -h, 0, -gap, h, 0, -gap, h, 2 * h, -gap, -h, 2 * h}),
                              b.add_indices({0, 1, 2, 0, 2, 3}));
  b.write(path, {b.add_node({{"mesh", floor}}), b.add_node({{"mesh", wall}})});
}

TEST(CliBakeAo, FootOfAWallAndDeterministicDumps) {
  TempDir dir;
  write_wall_scene(dir / "wall.gltf");
  const auto r = matbake({"--json", "bake-ao", (dir / "wall.gltf").string(), "--dump", (dir / "ao.csv").string(),
                          "--samples", "2048", "--falloff", "none", "--max-distance", "1e5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["vertices"], 9);
  std::ifstream csv(dir / "ao.csv");
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(header, "node,mesh,primitive,vertex,x,y,z,ao");
  const double ao = std::stod(first.substr(first.rfind(',') + 1));
  EXPECT_NEAR(ao, 0.5, 3 * std::sqrt(0.25 / 2048));  // 3σ of the binary estimator
  for (const char* jobs : {"1", "2"}) {
    const auto run = matbake({"-q", "--jobs", jobs, "bake-ao", (dir / "wall.gltf").string(), "--dump",
                              (dir / (std::string("ao") + jobs + ".bin")).string(), "--seed", "3"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  EXPECT_EQ(read_bytes(dir / "ao1.bin"), read_bytes(dir / "ao2.bin"));
  EXPECT_EQ(read_bytes(dir / "ao1.bin").size(), 9 * sizeof(float));
}

// The written scene passes the Khronos glTF-Validator with no error and no warning, in both
// containers and both attributes, and the input is left as it was.
TEST(CliBakeAo, WrittenScenesAreValidatorClean) {
  TempDir dir;
  write_wall_scene(dir / "wall.gltf");
  const std::string input = read_bytes(dir / "wall.gltf");
  for (const char* into : {"COLOR_0", "_AO"}) {
    for (const char* ext : {".gltf", ".glb"}) {
      const fs::path out = dir / (std::string("wall") + into + ext);
      const auto r = matbake({"-q", "bake-ao", (dir / "wall.gltf").string(), "-o", out.string(), "--into", into,
                              "--samples", "64"});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      MATBAKE_VALIDATE_OR_SKIP(report, out);
      EXPECT_EQ(report->errors, 0) << report->summary;
      EXPECT_EQ(report->warnings, 0) << report->summary;
    }
  }
  EXPECT_EQ(read_bytes(dir / "wall.gltf"), input);
}

TEST(CliBakeAo, BadScenesAndUsage) {
  TempDir dir;
  write_wall_scene(dir / "good.gltf");
  std::ofstream(dir / "broken.gltf") << "{\"asset\": ";
  {
    nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / "good.gltf"));
    doc["buffers"][0]["uri"] = "../../etc/passwd";
    std::ofstream(dir / "escape.gltf") << doc.dump();
  }
  const std::string dump = (dir / "out.csv").string();
  for (const auto& [file, problem] :
       {std::pair{(dir / "broken.gltf").string(), "not a valid glTF"},
        std::pair{(dir / "escape.gltf").string(), "URI '../../etc/passwd' is outside the glTF's folder"},
        std::pair{(dir / "missing.gltf").string(), "no such file"}}) {
    const auto r = matbake({"bake-ao", file, "--dump", dump});
    EXPECT_EQ(r.exit_code, 1) << file;
    expect_one_error_line(r, file, problem);
  }
  const std::string good = (dir / "good.gltf").string();
  EXPECT_EQ(matbake({"bake-ao", good, "--dump", dump, "--samples", "0"}).exit_code, 2);
  EXPECT_EQ(matbake({"bake-ao", good, "--dump", dump, "--falloff", "cubic"}).exit_code, 2);
  EXPECT_EQ(matbake({"bake-ao", good, "--dump", (dir / "out.txt").string()}).exit_code, 2);
  EXPECT_FALSE(fs::exists(dump));
  const std::string before = read_bytes(dir / "good.gltf");
  using Case = std::pair<std::vector<std::string>, std::string>;
  for (const auto& [args, problem] :
       {Case{{"bake-ao", good}, "bake-ao writes a glTF, a dump or both"},
        Case{{"bake-ao", good, "-o", good}, good + ": is an input; matbake never overwrites its inputs"},
        Case{{"bake-ao", good, "-o", (dir / "out.obj").string()}, (dir / "out.obj").string() + ": the output is .gltf or .glb"},
        Case{{"bake-ao", good, "-o", (dir / "x.glb").string(), "--into", "COLOR_1"}, "--into: 'COLOR_1': use COLOR_0 or _AO"}}) {
    const auto r = matbake(args);
    EXPECT_EQ(r.exit_code, 2) << problem;
    expect_one_error_line(r, "", problem);
  }
  EXPECT_EQ(read_bytes(dir / "good.gltf"), before);
  EXPECT_EQ(list_folder(dir.path()), (std::vector<std::string>{"broken.gltf", "escape.gltf", "good.gltf"}));
}

// A UV-mapped floor (half-size 1, material 0) under a ceiling 1 above it (half-size 1000, material 1,
// no UVs). With `own_occlusion`, material 0 has an occlusion texture of its own: a 4×4 PNG of 0.5.
void write_floor_scene(const fs::path& path, bool own_occlusion) {
  GltfBuilder b;
  const float h = 1000;
  const int floor = b.add_mesh(b.add_vec3({0, 0, 0, -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}),
                               b.add_indices({0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1}));
  b.doc["meshes"][floor]["primitives"][0]["attributes"]["TEXCOORD_0"] =
      b.add_floats({0.5f, 0.5f, 0, 0, 1, 0, 1, 1, 0, 1}, "VEC2", 2);
  b.doc["meshes"][floor]["primitives"][0]["material"] = 0;
  const int ceiling = b.add_mesh(b.add_vec3({-h, -h, 1, -h, h, 1, h, h, 1, h, -h, 1}), b.add_indices({0, 1, 2, 0, 2, 3}));
  b.doc["meshes"][ceiling]["primitives"][0]["material"] = 1;
  b.doc["materials"] = {{{"name", "floor"}}, {{"name", "ceiling"}}};
  if (own_occlusion) {
    image::Image own;
    own.width = own.height = 4, own.channels = 1, own.channel_names = {"Y"};
    own.pixels.assign(16, 0.5f);
    image::WriteOptions png;
    png.type = image::SampleType::u8;
    ASSERT_TRUE(image::write_image(own, path.parent_path() / "own.png", png));
    b.doc["images"] = {{{"uri", "own.png"}}};
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["materials"][0]["occlusionTexture"] = {{"index", 0}, {"strength", 0.9}};
  }
  b.write(path, {b.add_node({{"mesh", floor}}), b.add_node({{"mesh", ceiling}})});
}

// The texture's texels, as a viewer reads the material's occlusion texture (its red channel).
std::vector<float> occlusion_texels(const fs::path& file, int material = 0) {
  const auto doc = gltf::read_document(file);
  EXPECT_TRUE(doc) << doc.error().to_string();
  if (!doc) return {};
  const auto& info = doc->json["materials"][material]["occlusionTexture"];
  const auto& texture = doc->json["textures"][info["index"].get<std::size_t>()];
  const bool webp = !texture.contains("source");  // then named through EXT_texture_webp
  const std::size_t source = (webp ? texture["extensions"]["EXT_texture_webp"]["source"] : texture["source"]).get<std::size_t>();
  const auto bytes = gltf::image_bytes(*doc, source);
  EXPECT_TRUE(bytes);
  const auto img = image::decode_image({reinterpret_cast<const unsigned char*>(bytes->data()), bytes->size()},
                                       webp ? "occlusion.webp" : "occlusion.png", color::Transfer::linear);
  EXPECT_TRUE(img) << img.error().to_string();
  if (!img) return {};
  std::vector<float> red;  // what a viewer reads (a grey image's only channel)
  for (std::size_t i = 0; i < img->pixels.size(); i += std::size_t(img->channels)) red.push_back(img->pixels[i]);
  return red;
}

// The floor's texels are (h/D)² (binary AO of range D under an endless ceiling) in a 16-bit PNG,
// both containers are validator-clean, material 1 (no UVs) is left alone with a note, and the
// float EXR dump holds the same values.
TEST(CliBakeAo, TextureOfAFloorUnderACeiling) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", false);
  const std::string input = read_bytes(dir / "floor.gltf");
  const int n = 1024;
  for (const char* ext : {".gltf", ".glb"}) {
    const fs::path out = dir / "out" / (std::string("floor") + ext);
    fs::create_directories(dir / "out" / "exr");
    const auto r = matbake({"--json", "bake-ao", (dir / "floor.gltf").string(), "-o", out.string(), "--texture", "8x4",
                            "--bits", "16", "--samples", std::to_string(n), "--falloff", "none", "--max-distance", "2",
                            "--dump-texture", (dir / "out" / "exr").string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto report = nlohmann::json::parse(r.out);
    ASSERT_EQ(report["textures"].size(), 1u);
    EXPECT_EQ(report["textures"][0]["covered"], 32);
    EXPECT_EQ(report["texels"], 32);
    EXPECT_EQ(report["rays"], 32 * n);
    ASSERT_EQ(report["notes"].size(), 1u);
    EXPECT_NE(report["notes"][0].get<std::string>().find("has no TEXCOORD_0"), std::string::npos) << report["notes"];
    const std::vector<float> texels = occlusion_texels(out);
    ASSERT_EQ(texels.size(), 32u);
    for (float v : texels) EXPECT_NEAR(v, 0.25, 3 * std::sqrt(0.25 * 0.75 / n) + 0.5 / 65535);
    const auto exr = image::read_image(dir / "out" / "exr" / "floor_occlusion_0.exr", color::Transfer::linear);
    ASSERT_TRUE(exr) << exr.error().to_string();
    for (std::size_t i = 0; i < texels.size(); ++i) EXPECT_NEAR(exr->pixels[i], texels[i], 0.5 / 65535);
    MATBAKE_VALIDATE_OR_SKIP(validated, out);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
    EXPECT_EQ(validated->warnings, 0) << validated->summary;
  }
  EXPECT_EQ(read_bytes(dir / "floor.gltf"), input);
}

// A material's own occlusion texture (0.5 everywhere) is multiplied in by default, or replaced;
// either way its strength stays, and the file's texture is left in place.
TEST(CliBakeAo, TextureMultipliesOrReplacesTheMaterialsOwn) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", true);
  const int n = 1024;
  for (const char* existing : {"multiply", "replace"}) {
    const fs::path out = dir / (std::string(existing) + ".glb");
    const auto r = matbake({"-q", "bake-ao", (dir / "floor.gltf").string(), "-o", out.string(), "--texture", "4",
                            "--samples", std::to_string(n), "--falloff", "none", "--max-distance", "2",
                            "--existing-occlusion", existing});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const double scale = std::string(existing) == "multiply" ? 0.5 : 1.0;
    for (float v : occlusion_texels(out)) EXPECT_NEAR(v, 0.25 * scale, scale * 3 * std::sqrt(0.25 * 0.75 / n) + 0.5 / 255);
    const auto doc = gltf::read_document(out);
    ASSERT_TRUE(doc);
    EXPECT_EQ(doc->json["materials"][0]["occlusionTexture"]["strength"], 0.9);
    EXPECT_EQ(doc->json["images"].size(), 2u);
    MATBAKE_VALIDATE_OR_SKIP(validated, out);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
  }
}

// The material's own occlusion texture seen through its KHR_texture_transform: columns 0–1 of a 4×4
// texture are 0.25 and 2–3 are 1; an offset of half the width (repeat) lands each bake texel's centre
// on the centre of the texel two columns on, so the bake's columns 0–1 are multiplied by 1 and 2–3
// by 64/255 (a bilinear sample through the transform, in closed form). The new texture is over
// raw UVs: no transform, and the report says what became of the old one.
TEST(CliBakeAo, TextureMultipliesTheOwnThroughItsTransform) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", true);
  std::vector<double> codes;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) codes.push_back(x < 2 ? 64 : 255);
  }
  test::write_raw(dir / "own.png", 4, 4, 1, "uint8", codes);
  nlohmann::json doc = nlohmann::json::parse(read_bytes(dir / "floor.gltf"));
  doc["materials"][0]["occlusionTexture"]["extensions"] = {{"KHR_texture_transform", {{"offset", {0.5, 0}}}}};
  doc["extensionsUsed"] = {"KHR_texture_transform"};
  write_bytes(dir / "floor.gltf", doc.dump());
  const fs::path out = dir / "out.glb";
  const int n = 4096;
  const auto r = matbake({"--json", "bake-ao", (dir / "floor.gltf").string(), "-o", out.string(), "--texture", "4", "--samples",
                          std::to_string(n), "--falloff", "none", "--max-distance", "2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["textures"][0]["existing"], "multiplied, sampled through its KHR_texture_transform");
  const std::vector<float> texels = occlusion_texels(out);
  ASSERT_EQ(texels.size(), 16u);
  for (std::size_t i = 0; i < 16; ++i) {
    const double own = i % 4 < 2 ? 1.0 : 64.0 / 255;  // the bake itself is (h/D)² = 0.25 (see above)
    EXPECT_NEAR(texels[i], 0.25 * own, own * 3 * std::sqrt(0.25 * 0.75 / n) + 0.5 / 255) << "texel " << i;
  }
  const auto written = gltf::read_document(out);
  ASSERT_TRUE(written);
  EXPECT_FALSE(written->json["materials"][0]["occlusionTexture"].contains("extensions"));
  MATBAKE_VALIDATE_OR_SKIP(validated, out);
  EXPECT_EQ(validated->errors, 0) << validated->summary;
}

// One texture holds one mapping: occlusion and metallic-roughness with the same KHR_texture_transform
// are packed into one ORM texture that keeps it; mapped differently they stay apart and the report
// says why, both in export's packing and in an ORM bake.
TEST(CliBakeAo, OrmKeepsDifferentlyMappedMapsApart) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", true);
  std::vector<double> rgb(4 * 4 * 3, 128);
  test::write_raw(dir / "mr.png", 4, 4, 3, "uint8", rgb);
  const nlohmann::json base = nlohmann::json::parse(read_bytes(dir / "floor.gltf"));
  const nlohmann::json shifted = {{"KHR_texture_transform", {{"offset", {0.5, 0}}}}};
  const auto scene_with = [&](const nlohmann::json& occlusion_ext, const nlohmann::json& mr_ext) {
    nlohmann::json doc = base;
    doc["images"].push_back({{"uri", "mr.png"}});
    doc["textures"].push_back({{"source", 1}});
    doc["materials"][0]["pbrMetallicRoughness"] = {{"metallicRoughnessTexture", {{"index", 1}}}};
    if (!occlusion_ext.is_null()) doc["materials"][0]["occlusionTexture"]["extensions"] = occlusion_ext;
    if (!mr_ext.is_null()) doc["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["extensions"] = mr_ext;
    doc["extensionsUsed"] = {"KHR_texture_transform"};
    write_bytes(dir / "scene.gltf", doc.dump());
    return (dir / "scene.gltf").string();
  };
  const auto material_of = [](const fs::path& file) {
    const auto doc = gltf::read_document(file);
    EXPECT_TRUE(doc);
    return doc ? nlohmann::json::parse(doc->json["materials"][0].dump()) : nlohmann::json();
  };
  {
    const fs::path out = dir / "same.glb";
    const auto r = matbake({"-q", "export", scene_with(shifted, shifted), "-o", out.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json m = material_of(out);
    EXPECT_EQ(m["occlusionTexture"]["index"], m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"]);
    EXPECT_EQ(m["occlusionTexture"]["extensions"], shifted);
    EXPECT_EQ(m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["extensions"], shifted);
    MATBAKE_VALIDATE_OR_SKIP(validated, out);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
  }
  {
    const fs::path out = dir / "apart.glb";
    const auto r = matbake({"--json", "export", scene_with(shifted, nullptr), "-o", out.string()});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(nlohmann::json::parse(r.out)["materials"][0]["action"].get<std::string>().find("kept apart (mapped differently"),
              std::string::npos) << r.out;
    const nlohmann::json m = material_of(out);
    EXPECT_NE(m["occlusionTexture"]["index"], m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"]);
  }
  {
    const fs::path out = dir / "baked.glb";
    const auto r = matbake({"--json", "export", scene_with(nullptr, shifted), "-o", out.string(), "--ao-texture", "4", "--ao-samples", "16"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["ao_textures"][0]["orm"],
              "kept apart: the metallic-roughness texture has a KHR_texture_transform, the bake none");
    const nlohmann::json m = material_of(out);
    EXPECT_NE(m["occlusionTexture"]["index"], m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"]);
    EXPECT_EQ(m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["extensions"], shifted);
    MATBAKE_VALIDATE_OR_SKIP(validated, out);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
  }
}

// Images as delivered files hold them: an occlusion texture only in WebP (EXT_texture_webp) is decoded
// and multiplied in; one only in KTX2 (KHR_texture_basisu, no decoder here) is passed through byte for
// byte when the work needs none of its texels, and is one error naming the texture when it does.
TEST(CliBakeAo, WebpIsDecodedAndKtx2PassedThrough) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", true);
  const nlohmann::json base = nlohmann::json::parse(read_bytes(dir / "floor.gltf"));
  const int n = 1024;
  {
    test::write_raw(dir / "own.webp", 4, 4, 3, "uint8", std::vector<double>(48, 128));
    nlohmann::json doc = base;
    doc["images"][0] = {{"uri", "own.webp"}};
    doc["textures"][0] = {{"extensions", {{"EXT_texture_webp", {{"source", 0}}}}}};
    doc["extensionsUsed"] = doc["extensionsRequired"] = {"EXT_texture_webp"};
    write_bytes(dir / "webp.gltf", doc.dump());
    const fs::path out = dir / "webp.glb";
    const auto r = matbake({"-q", "bake-ao", (dir / "webp.gltf").string(), "-o", out.string(), "--texture", "4", "--samples",
                            std::to_string(n), "--falloff", "none", "--max-distance", "2"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (float v : occlusion_texels(out)) EXPECT_NEAR(v, 0.25 * 128 / 255, 3 * std::sqrt(0.25 * 0.75 / n) + 2.0 / 255);
    MATBAKE_VALIDATE_OR_SKIP(validated, out);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
  }
  const std::string ktx2 = std::string("\xabKTX 20\xbb\r\n\x1a\n", 12) + std::string(68, '\0');
  write_bytes(dir / "own.ktx2", ktx2);
  nlohmann::json doc = base;
  doc["images"][0] = {{"uri", "own.ktx2"}, {"mimeType", "image/ktx2"}};
  doc["textures"][0] = {{"extensions", {{"KHR_texture_basisu", {{"source", 0}}}}}};
  doc["extensionsUsed"] = doc["extensionsRequired"] = {"KHR_texture_basisu"};
  write_bytes(dir / "ktx2.gltf", doc.dump());
  const auto needs_texels = matbake({"bake-ao", (dir / "ktx2.gltf").string(), "-o", (dir / "multiplied.glb").string(), "--texture", "4"});
  EXPECT_EQ(needs_texels.exit_code, 1);
  EXPECT_EQ(needs_texels.err, "matbake: error: " + (dir / "ktx2.gltf").string() +
                                  ": /textures/0: its only image is KTX2 (KHR_texture_basisu), which matbake cannot decode, and this "
                                  "work needs its texels\n");
  EXPECT_FALSE(fs::exists(dir / "multiplied.glb"));
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--texture", "4", "--existing-occlusion", "replace"}, std::vector<std::string>{}}) {
    std::vector<std::string> command = {"-q", "bake-ao", (dir / "ktx2.gltf").string(), "-o", (dir / "out.glb").string()};
    command.insert(command.end(), args.begin(), args.end());
    const auto r = matbake(command);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto written = gltf::read_document(dir / "out.glb");
    ASSERT_TRUE(written);
    const auto bytes = gltf::image_bytes(*written, 0);
    ASSERT_TRUE(bytes);
    EXPECT_EQ(*bytes, ktx2);
  }
}

// --texture-format webp: the occlusion texture as lossless WebP named through EXT_texture_webp (which
// the file then requires), its texels the PNG run's exactly; 16 bits cannot be WebP.
TEST(CliBakeAo, TexturesAreWrittenAsLosslessWebpWhenAsked) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", false);
  const std::vector<std::string> bake = {"-q", "bake-ao", (dir / "floor.gltf").string(), "--texture", "8", "--samples", "64"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = bake;
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  const auto png = with({"-o", (dir / "png.glb").string()});
  ASSERT_EQ(png.exit_code, 0) << png.err;
  const auto webp = with({"-o", (dir / "webp.gltf").string(), "--texture-format", "webp"});
  ASSERT_EQ(webp.exit_code, 0) << webp.err;
  EXPECT_TRUE(fs::exists(dir / "webp_floor_occlusion.webp"));  // named from its material
  EXPECT_EQ(occlusion_texels(dir / "png.glb"), occlusion_texels(dir / "webp.gltf"));
  const auto doc = gltf::read_document(dir / "webp.gltf");
  ASSERT_TRUE(doc);
  const nlohmann::json& texture = doc->json["textures"][doc->json["materials"][0]["occlusionTexture"]["index"].get<std::size_t>()];
  EXPECT_FALSE(texture.contains("source"));
  EXPECT_EQ(doc->json["images"][texture["extensions"]["EXT_texture_webp"]["source"].get<std::size_t>()]["mimeType"], "image/webp");
  EXPECT_EQ(doc->json["extensionsRequired"], nlohmann::json::array({"EXT_texture_webp"}));
  MATBAKE_VALIDATE_OR_SKIP(validated, dir / "webp.gltf");
  EXPECT_EQ(validated->errors, 0) << validated->summary;
  EXPECT_EQ(validated->warnings, 0) << validated->summary;
  const auto deep = with({"-o", (dir / "deep.glb").string(), "--texture-format", "webp", "--bits", "16"});
  EXPECT_EQ(deep.exit_code, 1);
  EXPECT_NE(deep.err.find("WebP holds 8 bits per channel"), std::string::npos) << deep.err;
  EXPECT_EQ(std::count(deep.err.begin(), deep.err.end(), '\n'), 1) << deep.err;
  EXPECT_FALSE(fs::exists(dir / "deep.glb"));
}

// One UV-mapped quad placed twice: under the ceiling ((h/D)² = 0.25) and 10 units away, open (1).
// By default its texture averages the placements (0.625) and says so; --per-instance gives the
// second placement a copy of the mesh and of the material, each with its own texture.
TEST(CliBakeAo, TexturePerInstance) {
  TempDir dir;
  GltfBuilder b;
  const float h = 1000;
  const int quad = b.add_mesh(b.add_vec3({0, 0, 0, -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}),
                              b.add_indices({0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1}));
  b.doc["meshes"][quad]["primitives"][0]["attributes"]["TEXCOORD_0"] =
      b.add_floats({0.5f, 0.5f, 0, 0, 1, 0, 1, 1, 0, 1}, "VEC2", 2);
  b.doc["meshes"][quad]["primitives"][0]["material"] = 0;
  const int ceiling = b.add_mesh(b.add_vec3({-h, -h, 1, -h, h, 1, h, h, 1, h, -h, 1}), b.add_indices({0, 1, 2, 0, 2, 3}));
  b.doc["materials"] = {{{"name", "tile"}}};
  b.write(dir / "twice.gltf", {b.add_node({{"mesh", quad}, {"name", "under"}}), b.add_node({{"mesh", ceiling}}),
                               b.add_node({{"mesh", quad}, {"name", "open"}, {"translation", {2 * h + 10, 0, 0}}})});
  const int n = 1024;
  const double sigma = std::sqrt(0.25 * 0.75 / n);
  const std::vector<std::string> common = {"--texture", "4", "--samples", std::to_string(n), "--falloff", "none",
                                           "--max-distance", "2"};
  std::vector<std::string> args = {"--json", "bake-ao", (dir / "twice.gltf").string(), "-o", (dir / "mean.glb").string()};
  args.insert(args.end(), common.begin(), common.end());
  auto r = matbake(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["textures"].size(), 1u);
  EXPECT_EQ(report["textures"][0]["overlapped"], 16);
  EXPECT_NE(report["notes"].dump().find("is placed by 2 nodes; its texels hold the mean of the placements"), std::string::npos);
  for (float v : occlusion_texels(dir / "mean.glb")) EXPECT_NEAR(v, 0.625, 3 * sigma / 2 + 0.5 / 255);

  args[4] = (dir / "each.glb").string();
  args.push_back("--per-instance");
  r = matbake(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["textures"].size(), 2u);
  EXPECT_EQ(report["textures"][0]["overlapped"], 0);
  EXPECT_EQ(report["textures"][1]["material"], 1);
  EXPECT_EQ(report["textures"][1]["name"], "tile (open)");
  for (float v : occlusion_texels(dir / "each.glb", 0)) EXPECT_NEAR(v, 0.25, 3 * sigma + 0.5 / 255);
  for (float v : occlusion_texels(dir / "each.glb", 1)) EXPECT_EQ(v, 1.0f);
  const auto doc = gltf::read_document(dir / "each.glb");
  ASSERT_TRUE(doc);
  EXPECT_EQ(doc->json["meshes"].size(), 3u);  // the quad, the ceiling, the quad's copy for "open"
  EXPECT_EQ(doc->json["nodes"][2]["mesh"], 2);
  EXPECT_EQ(doc->json["meshes"][2]["primitives"][0]["material"], 1);
  EXPECT_EQ(doc->json["meshes"][2]["primitives"][0]["attributes"], doc->json["meshes"][0]["primitives"][0]["attributes"]);

  // A name that is not a string (the validator's TYPE_MISMATCH) was copied into the output: the
  // file is refused as it is read, naming the property (gltf/types.hpp).
  nlohmann::json numbered = nlohmann::json::parse(read_bytes(dir / "twice.gltf"));
  numbered["materials"][0]["name"] = 7;
  write_bytes(dir / "numbered.gltf", numbered.dump());
  args[2] = (dir / "numbered.gltf").string(), args[4] = (dir / "numbered.glb").string();
  r = matbake(args);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "matbake: error: " + (dir / "numbered.gltf").string() + ": /materials/0/name: 7 is not a string\n");
  EXPECT_FALSE(fs::exists(dir / "numbered.glb"));

  MATBAKE_VALIDATE_OR_SKIP(validated, dir / "each.glb");
  EXPECT_EQ(validated->errors, 0) << validated->summary;
  EXPECT_EQ(validated->warnings, 0) << validated->summary;
}

TEST(CliBakeAo, TextureUsageAndScenesWithNothingToHoldIt) {
  TempDir dir;
  write_floor_scene(dir / "floor.gltf", false);
  write_wall_scene(dir / "wall.gltf");  // no materials
  const std::string floor = (dir / "floor.gltf").string(), out = (dir / "out.glb").string();
  using Case = std::pair<std::vector<std::string>, std::string>;
  for (const auto& [args, problem] :
       {Case{{"--texture", "big"}, "--texture: 'big': a size such as 1024 or 2048x1024"},
        Case{{"--texture", "0"}, "--texture: '0': a size such as 1024 or 2048x1024"},
        Case{{"--texture", "64x99999"}, "AO texture sides must be 1 to 16384 texels"},
        Case{{"--texture", "64", "--bits", "12"}, "--bits: '12': 8 or 16"},
        Case{{"--texture", "64", "--texel-samples", "100", "--samples", "64"}, "AO texel samples must be 1 to the sample count (64)"},
        Case{{"--texture", "64", "--existing-occlusion", "add"}, "--existing-occlusion: 'add': use multiply or replace"},
        Case{{"--texture", "64", "--dump", (dir / "v.csv").string()},
             (dir / "v.csv").string() + ": --dump holds per-vertex values; with --texture use --dump-texture"}}) {
    std::vector<std::string> command = {"bake-ao", floor, "-o", out};
    command.insert(command.end(), args.begin(), args.end());
    const auto r = matbake(command);
    EXPECT_EQ(r.exit_code, 2) << problem;
    expect_one_error_line(r, "", problem);
  }
  const auto r = matbake({"bake-ao", (dir / "wall.gltf").string(), "-o", out, "--texture", "64"});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, (dir / "wall.gltf").string(),
                        "no material the scene reaches can hold an occlusion texture (each needs a UV set on all its primitives)");
  EXPECT_EQ(list_folder(dir.path()), (std::vector<std::string>{"floor.gltf", "wall.gltf"}));
}

}  // namespace
}  // namespace matbake::test
