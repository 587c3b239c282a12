// `matbake inspect`: its figures against the files, read here from the containers themselves (glTF
// JSON and GLB chunks, PNG and JPEG headers, the KTX2 header), GPU memory by its formula, and its
// --json against docs/inspect.schema.json (checked by python3-jsonschema, Debian's).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstring>

#include "matbake/ktx2.hpp"
#include "support/basisu.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {
namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kInspectTestdata = fs::path(MATBAKE_TESTDATA_DIR) / "gltf";

json inspect_json(const fs::path& path) {
  const RunResult r = matbake({"--json", "inspect", path.string()});
  EXPECT_EQ(r.exit_code, 0) << path << ": " << r.err;
  const json j = json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.out;
  return j;
}

// The problems docs/inspect.schema.json finds in each file ("" when all are valid), or nullopt
// when python3's jsonschema is not installed (scripts/deps.sh installs it).
std::optional<std::string> schema_problems(const std::vector<fs::path>& files) {
  if (run("/usr/bin/python3", {"-c", "import jsonschema"}).exit_code != 0) return std::nullopt;
  std::vector<std::string> args{"-c",
                                "import json, sys, jsonschema\n"
                                "schema = json.load(open(sys.argv[1]))\n"
                                "v = jsonschema.Draft202012Validator(schema)\n"
                                "for f in sys.argv[2:]:\n"
                                "    for e in v.iter_errors(json.load(open(f))):\n"
                                "        print(f, '/'.join(map(str, e.absolute_path)), e.message)\n",
                                (fs::path(MATBAKE_SOURCE_DIR) / "docs/inspect.schema.json").string()};
  for (const fs::path& f : files) args.push_back(f.string());
  const RunResult r = run("/usr/bin/python3", args);
  return r.out + (r.exit_code ? r.err : "");
}

std::uint32_t big_endian32(const unsigned char* p) { return std::uint32_t(p[0]) << 24 | p[1] << 16 | p[2] << 8 | p[3]; }
std::uint32_t little_endian32(const unsigned char* p) { return std::uint32_t(p[3]) << 24 | p[2] << 16 | p[1] << 8 | p[0]; }

// Width and height from the image's own header: PNG's IHDR, JPEG's start-of-frame, KTX2's header.
std::pair<std::uint32_t, std::uint32_t> header_size(const std::string& bytes) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  if (bytes.size() >= 24 && bytes.compare(1, 3, "PNG") == 0) return {big_endian32(p + 16), big_endian32(p + 20)};
  if (bytes.size() >= 28 && bytes.compare(1, 6, "KTX 20") == 0) return {little_endian32(p + 20), little_endian32(p + 24)};
  for (std::size_t at = 2; at + 9 < bytes.size();) {  // JPEG: markers until a SOFn
    if (p[at] != 0xFF) return {0, 0};
    const int marker = p[at + 1];
    const std::size_t length = std::size_t(p[at + 2]) << 8 | p[at + 3];
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      return {std::uint32_t(p[at + 7]) << 8 | p[at + 8], std::uint32_t(p[at + 5]) << 8 | p[at + 6]};
    }
    at += 2 + length;
  }
  return {0, 0};
}

std::string base64_decode(const std::string& text) {
  static const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    const std::size_t v = digits.find(c);
    if (v == std::string::npos) continue;
    bits = bits << 6 | std::uint32_t(v);
    if ((count += 6) >= 8) out.push_back(char(bits >> (count -= 8) & 0xFF));
  }
  return out;
}

// A glTF's JSON and binary chunk, read here (not through matbake).
struct Container {
  json doc;
  std::string bin;
};

Container read_container(const fs::path& path) {
  const std::string bytes = read_bytes(path);
  if (path.extension() != ".glb") return {json::parse(bytes), ""};
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::uint32_t json_length = little_endian32(p + 12);
  Container c{json::parse(bytes.substr(20, json_length)), ""};
  if (20 + json_length + 8 <= bytes.size()) c.bin = bytes.substr(20 + json_length + 8, little_endian32(p + 20 + json_length));
  return c;
}

std::string uri_bytes(const fs::path& folder, const std::string& uri) {
  if (uri.rfind("data:", 0) == 0) return base64_decode(uri.substr(uri.find(',') + 1));
  return read_bytes(folder / uri);
}

std::string image_bytes_of(const fs::path& path, const Container& c, const json& image) {
  if (image.contains("uri")) return uri_bytes(path.parent_path(), image["uri"]);
  const json& view = c.doc["bufferViews"][image["bufferView"].get<std::size_t>()];
  const json& buffer = c.doc["buffers"][view["buffer"].get<std::size_t>()];
  const std::string data = buffer.contains("uri") ? uri_bytes(path.parent_path(), buffer["uri"]) : c.bin;
  return data.substr(view.value("byteOffset", 0), view["byteLength"].get<std::size_t>());
}

// Every image's bytes and size as its container holds them; the totals their sum.
void expect_figures_of_the_files(const fs::path& path, const json& inspected) {
  const Container c = read_container(path);
  const json& images = inspected["images"];
  ASSERT_EQ(images.size(), c.doc.value("images", json::array()).size()) << path;
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const std::string bytes = image_bytes_of(path, c, c.doc["images"][i]);
    const auto [width, height] = header_size(bytes);
    EXPECT_EQ(images[i]["bytes"], bytes.size()) << path << " image " << i;
    EXPECT_EQ(images[i]["width"], width) << path << " image " << i;
    EXPECT_EQ(images[i]["height"], height) << path << " image " << i;
    total += bytes.size();
  }
  EXPECT_EQ(inspected["totals"]["image_bytes"], total) << path;
  EXPECT_EQ(inspected["textures"].size(), c.doc.value("textures", json::array()).size()) << path;
  EXPECT_EQ(inspected["materials"].size(), c.doc.value("materials", json::array()).size()) << path;
}

// gpu_bytes' closed form for an 8 × 4 image with its full chain (8×4, 4×2, 2×1, 1×1): 43 texels of
// 4 bytes; blocks of 16 bytes: 2 + 1 + 1 + 1.
constexpr std::uint64_t kRgba8Of8x4 = (32 + 8 + 2 + 1) * 4, kBlocksOf8x4 = (2 + 1 + 1 + 1) * 16;

// A file written here: a mesh of two triangles placed twice, a PNG twice (the second a copy: a
// duplicate), one read as colour and one as a normal map.
TEST(Inspect, FiguresOfAGltfWrittenHere) {
  TempDir dir;
  write_raw(dir / "a.png", 8, 4, 4, "uint8", std::vector<double>(8 * 4 * 4, 100));
  fs::copy_file(dir / "a.png", dir / "b.png");
  GltfBuilder b;
  const int positions = b.add_vec3({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
  const int uv = b.add_floats({0, 0, 1, 0, 1, 1, 0, 1}, "VEC2", 2);
  const int mesh = b.add_mesh(positions, b.add_indices({0, 1, 2, 0, 2, 3}));
  b.doc["meshes"][mesh]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
  b.doc["meshes"][mesh]["primitives"][0]["material"] = 0;
  b.doc["images"] = {{{"uri", "a.png"}}, {{"uri", "b.png"}}};
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  b.doc["materials"] = {{{"name", "paint"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                         {"normalTexture", {{"index", 1}, {"texCoord", 0}}}}};
  const int first = b.add_node({{"mesh", mesh}}), second = b.add_node({{"mesh", mesh}, {"translation", {2, 0, 0}}});
  b.write(dir / "s.gltf", {first, second});

  const json j = inspect_json(dir / "s.gltf")["inspected"];
  EXPECT_EQ(j["kind"], "gltf");
  EXPECT_EQ(j["scenes"][0]["mesh_placements"], 2);
  EXPECT_EQ(j["scenes"][0]["triangles"], 4);
  EXPECT_EQ(j["meshes"][0]["triangles"], 2);
  EXPECT_EQ(j["meshes"][0]["vertices"], 4);
  EXPECT_EQ(j["meshes"][0]["attributes"]["TEXCOORD_0"], "VEC2 float");
  EXPECT_EQ(j["materials"][0]["workflow"], "metal-rough");
  // In the file's order (the builder writes keys sorted).
  EXPECT_EQ(j["materials"][0]["slots"][0], json({{"slot", "normalTexture"}, {"texture", 1}, {"texcoord", 0}, {"transform", false}}));
  EXPECT_EQ(j["textures"][1]["used_by"][0]["class"], "normal");
  EXPECT_EQ(j["textures"][0]["used_by"][0]["class"], "colour");
  EXPECT_EQ(j["images"][0]["bytes"], fs::file_size(dir / "a.png"));
  EXPECT_EQ(j["images"][1]["duplicate_of"], 0);
  EXPECT_EQ(j["images"][0]["gpu_bytes"], json({{"rgba8", kRgba8Of8x4}, {"block_4x4", kBlocksOf8x4}}));
  EXPECT_EQ(j["totals"]["gpu_bytes"], json({{"rgba8", 2 * kRgba8Of8x4}, {"block_4x4", 2 * kBlocksOf8x4}}));
  expect_figures_of_the_files(dir / "s.gltf", j);
  const RunResult text = matbake({"inspect", (dir / "s.gltf").string()});
  EXPECT_NE(text.out.find("totals: 4 triangles in the default scene, 4 vertices"), std::string::npos) << text.out;
}

// A KTX2 file written here: UASTC 8×8 with its chain of 4 levels, no supercompression.
TEST(Inspect, HeaderAndLevelsOfAKtx2WrittenHere) {
  TempDir dir;
  ktx2::UastcFile file{.width = 8, .height = 8, .transfer = ktx2::kTransferSRGB, .channel = ktx2::kUastcRGBA, .writer = "test"};
  for (std::size_t blocks : {4, 1, 1, 1}) file.levels.push_back(*ktx2::uastc_level(std::vector<unsigned char>(blocks * 16, 7), 0));
  const auto bytes = ktx2::write_uastc(file);
  ASSERT_TRUE(bytes);
  write_bytes(dir / "t.ktx2", std::string(bytes->begin(), bytes->end()));
  const json j = inspect_json(dir / "t.ktx2")["inspected"];
  EXPECT_EQ(j["bytes"], bytes->size());
  EXPECT_EQ(j["header"]["width"], 8);
  EXPECT_EQ(j["header"]["levels"], 4);
  EXPECT_EQ(j["header"]["supercompression"], "none");
  EXPECT_EQ(j["descriptor"]["codec"], "uastc");
  EXPECT_EQ(j["descriptor"]["transfer"], "srgb");
  EXPECT_EQ(j["descriptor"]["primaries"], "bt709");
  EXPECT_EQ(j["descriptor"]["channels"], json({ktx2::kUastcRGBA}));
  EXPECT_EQ(j["levels"][0], json({{"level", 0}, {"width", 8}, {"height", 8}, {"bytes", 64}, {"uncompressed_bytes", 64}}));
  EXPECT_EQ(j["levels"][3]["width"], 1);
  EXPECT_EQ(j["key_values"]["KTXwriter"], "test");
  EXPECT_EQ(j["gpu_bytes"], json({{"rgba8", (64 + 16 + 4 + 1) * 4}, {"block_4x4", (4 + 1 + 1 + 1) * 16}}));
}

TEST(Inspect, RefusesWhatItCannotRead) {
  TempDir dir;
  write_bytes(dir / "x.txt", "hello");
  RunResult r = matbake({"inspect", (dir / "x.txt").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "matbake: error: " + (dir / "x.txt").string() + ": matbake inspects .gltf, .glb, .ktx2 and manifests (.toml)\n");
  write_bytes(dir / "bad.ktx2", "KTX but not");
  r = matbake({"inspect", (dir / "bad.ktx2").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.rfind("matbake: error: " + (dir / "bad.ktx2").string() + ": ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// A manifest's jobs from their stamps: none built, all built, one changed, one failing.
TEST(Inspect, AManifestsJobsAsTheStampsHaveThem) {
  TempDir dir;
  copy_example(dir.path(), true);
  const fs::path manifest = dir / "showroom.toml";
  json j = inspect_json(manifest)["inspected"];
  ASSERT_EQ(j["jobs"].size(), 6u);
  EXPECT_EQ(j["counts"], json({{"up_to_date", 0}, {"out_of_date", 6}, {"failed", 0}}));
  EXPECT_EQ(j["jobs"][0]["reason"], "no earlier build");
  EXPECT_FALSE(fs::exists(dir / "out"));  // nothing written
  ASSERT_EQ(matbake({"build", manifest.string(), "--quiet"}).exit_code, 0);
  j = inspect_json(manifest)["inspected"];
  EXPECT_EQ(j["counts"], json({{"up_to_date", 6}, {"out_of_date", 0}, {"failed", 0}}));
  EXPECT_EQ(j["jobs"][5]["name"], "scene:showroom");
  EXPECT_EQ(j["jobs"][5]["outputs"], json({(dir / "out/showroom.glb").string()}));

  std::string text = read_bytes(manifest);
  text.replace(text.find("roughness = 0.85"), 16, "roughness = 0.5");
  write_bytes(manifest, text);
  fs::remove(dir / "textures/wood_albedo.png");
  const json whole = inspect_json(manifest);
  j = whole["inspected"];
  std::map<std::string, json> by_name;
  for (const json& job : j["jobs"]) by_name[job["name"]] = job;
  EXPECT_EQ(by_name["material:rubber"]["state"], "out_of_date");
  EXPECT_EQ(by_name["material:rubber"]["changed"][0]["parameter"], "sources.roughness");
  EXPECT_EQ(by_name["material:wood"]["state"], "failed");
  EXPECT_NE(by_name["material:wood"]["error"].get<std::string>().find(manifest.string() + ":"), std::string::npos);
  write_bytes(dir / "m.json", whole.dump());
  if (const auto problems = schema_problems({dir / "m.json"})) {
    EXPECT_EQ(*problems, "");
  }
}

// A scene that bakes: the plan exports the scene as it is, so the maps the bake adds are named as
// not estimated (in JSON and as the text's last line), and nothing is written.
TEST(Inspect, AScenesBakedMapsAreNamedAsNotEstimated) {
  TempDir dir;
  copy_example(dir.path(), false);
  write_bytes(dir / "b.toml", "output = \"out\"\n[scenes.s]\ninput = \"showroom.gltf\"\n"
                              "bake = { from = \"showroom.gltf\", maps = [\"normal\", \"ao\"], size = 64 }\n");
  const json inspected = inspect_json(dir / "b.toml");
  const json& delivery = inspected["inspected"]["jobs"][0]["delivery"];
  EXPECT_EQ(delivery["not_estimated"], "the bake's maps (normal, ao, 64x64 a baked material): made when the scene is built, not in this estimate");
  const RunResult text = matbake({"inspect", (dir / "b.toml").string()});
  EXPECT_NE(text.out.find("\n  not estimated: the bake's maps (normal, ao, 64x64"), std::string::npos) << text.out;
  EXPECT_FALSE(fs::exists(dir / "out"));
  write_bytes(dir / "b.json", inspected.dump());
  if (const auto problems = schema_problems({dir / "b.json"})) {
    EXPECT_EQ(*problems, "");
  }
}

// The scene job of a `build --json` or of `inspect --json` on a manifest.
json scene_job(const json& jobs) {
  for (const json& job : jobs) {
    if (job["name"] == "scene:showroom") return job;
  }
  ADD_FAILURE() << "no scene:showroom in " << jobs.dump();
  return json::object();
}

// A delivered texture's level errors (docs/delivery.md#level-error): every KTX2 level measured, a
// PSNR within what UASTC and ETC1S give on the example (26–99 dB; 99 an exact level), angles in
// [0°, 180°] for normal maps (the mean at most the max); nothing measured of a PNG.
void expect_levels_measured(const json& texture, bool ktx2) {
  if (!ktx2) {
    EXPECT_FALSE(texture.contains("level_error")) << texture.dump();
    return;
  }
  const json& levels = texture["level_error"];
  ASSERT_EQ(levels.size(), texture["levels"].get<std::size_t>()) << texture.dump();
  for (const json& l : levels) {
    EXPECT_GT(l["psnr"].get<double>(), 20) << texture.dump();
    EXPECT_LE(l["psnr"].get<double>(), 99) << texture.dump();
    if (texture["class"] == "normal") {
      EXPECT_GE(l["mean_angle"].get<double>(), 0);
      EXPECT_LE(l["mean_angle"].get<double>(), l["max_angle"].get<double>());
      EXPECT_LE(l["max_angle"].get<double>(), 180);
    } else {
      EXPECT_FALSE(l.contains("mean_angle"));
    }
  }
  EXPECT_GT(texture["seconds"].get<double>(), 0);
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// What inspect plans for the example's scene, delivered with `settings`, is what the build then
// delivers: every texture's number, class, codec, materials, needed side, size and levels. Bytes:
// a colour PNG kept at its size is its source's, exactly (the ORM textures hold AO, which a plan
// bakes with one ray a texel, so their PNG bytes differ); uncompressed UASTC counts 16 bytes a block of
// every level exactly, so only the header's key/value data (the writer's name, allowed 96 bytes)
// and each level's 16-byte alignment can differ.
void expect_planned_as_built(const std::string& settings, bool ktx2) {
  TempDir dir;
  copy_example(dir.path(), true);
  const fs::path manifest = dir / "showroom.toml";
  write_bytes(manifest, read_bytes(manifest) + settings);
  const json inspected = inspect_json(manifest);
  const json planned = scene_job(inspected["inspected"]["jobs"])["delivery"];
  EXPECT_FALSE(fs::exists(dir / "out")) << "a plan writes nothing";
  write_bytes(dir / "plan.json", inspected.dump());
  if (const auto problems = schema_problems({dir / "plan.json"})) {
    EXPECT_EQ(*problems, "");
  }
  const RunResult built = matbake({"--json", "build", manifest.string(), "--quiet", "--report"});
  ASSERT_EQ(built.exit_code, 0) << built.err;
  const json delivered = scene_job(json::parse(built.out)["jobs"])["details"]["textures"];
  ASSERT_EQ(planned["textures"].size(), delivered.size()) << planned.dump();
  ASSERT_EQ(delivered.size(), 15u) << "the example's scene has 15 textures";
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < delivered.size(); ++i) {
    const json& p = planned["textures"][i];
    const json& d = delivered[i];
    for (const char* key : {"texture", "class", "codec", "materials", "source_size", "size", "levels", "needed_side"}) {
      EXPECT_EQ(p.value(key, json()), d.value(key, json())) << key << " of texture " << i;
    }
    const std::uint64_t estimated = p["estimated_bytes"], bytes = d["bytes"];
    if (d["codec"] == "uastc") {
      EXPECT_LE(std::max(estimated, bytes) - std::min(estimated, bytes), 96u + 16u * d["levels"].get<std::uint64_t>()) << i;
    } else if (d["codec"] == "png" && d["size"] == d["source_size"] && d["class"] == "colour") {
      EXPECT_EQ(estimated, bytes) << i;
    }
    total += estimated;
    EXPECT_EQ(d["codec"] != "png", ktx2) << i;
    expect_levels_measured(d, ktx2);
  }
  EXPECT_EQ(planned["estimated_bytes"]["total"], total);
  // The report page shows every measured chain: a PSNR row per KTX2 texture, angles for normal maps.
  const std::string page = read_bytes(dir / "out/report.html");
  EXPECT_EQ(occurrences(page, "<div>PSNR (dB):"), ktx2 ? delivered.size() : 0u);
  std::size_t normals = 0;
  for (const json& d : delivered) normals += d["class"] == "normal";
  EXPECT_EQ(occurrences(page, "<div>angle mean (°):"), ktx2 ? normals : 0u);
}

TEST(Inspect, AScenesPlannedDeliveryIsWhatTheBuildDeliversPng) {
  expect_planned_as_built("texel_density = 64\n", false);
}

TEST(Inspect, AScenesPlannedDeliveryIsWhatTheBuildDeliversKtx2) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  expect_planned_as_built("texture_format = \"ktx2\"\ntexel_density = 64\ndata_zstd = 0\n", true);
}

// Every Khronos model of the shared test data: figures against the files, --json against the schema.
TEST(Inspect, EveryTestdataModelAgainstItsFilesAndTheSchema) {
  if (!fs::is_directory(kInspectTestdata)) GTEST_SKIP() << kInspectTestdata << " is absent (it comes with the project's shared folder, not with a clone)";
  TempDir dir;
  std::vector<fs::path> written;
  for (const auto& entry : fs::recursive_directory_iterator(kInspectTestdata)) {
    const fs::path& p = entry.path();
    if (p.extension() != ".gltf" && p.extension() != ".glb") continue;
    const json j = inspect_json(p);
    expect_figures_of_the_files(p, j["inspected"]);
    written.push_back(dir / (std::to_string(written.size()) + ".json"));
    write_bytes(written.back(), j.dump());
  }
  EXPECT_GE(written.size(), 20u);
  const auto problems = schema_problems(written);
  if (!problems) GTEST_SKIP() << "python3-jsonschema is not installed (scripts/deps.sh installs it): the schema was not checked";
  EXPECT_EQ(*problems, "");
}

// The example's outputs: its PNG scene, and the same delivered as KTX2 (every level read from the
// file matches the DFD's and the chain's sizes).
TEST(Inspect, TheExamplesOutputsPngAndKtx2) {
  MATBAKE_BASISU_OR_SKIP(basisu);
  TempDir dir;
  copy_example(dir.path(), true);
  ASSERT_EQ(matbake({"build", (dir / "showroom.toml").string(), "--quiet"}).exit_code, 0);
  const fs::path png = dir / "out/showroom.glb", ktx2_scene = dir / "ktx2.glb";
  const RunResult exported = matbake({"export", png.string(), "-o", ktx2_scene.string(), "--texture-format", "ktx2"});
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  std::vector<fs::path> written;
  for (const fs::path& scene : {png, ktx2_scene}) {
    const json j = inspect_json(scene);
    expect_figures_of_the_files(scene, j["inspected"]);
    for (const json& image : j["inspected"]["images"]) {
      EXPECT_EQ(image["format"], scene == png ? "png" : "ktx2");
      if (scene == ktx2_scene) {
        EXPECT_EQ(image["levels"], 9) << "256² has 9 levels";
      }
    }
    written.push_back(dir / (scene.stem().string() + ".json"));
    write_bytes(written.back(), j.dump());
  }
  if (const auto problems = schema_problems(written)) {
    EXPECT_EQ(*problems, "");
  }
}

}  // namespace
}  // namespace matbake::test
