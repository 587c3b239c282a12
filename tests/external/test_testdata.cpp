// Data nobody here wrote (../shared/testdata): PngSuite, libpng's test images and crashers, and the
// OpenEXR test images including damaged files. Skipped, with a message, where the folder is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include <fstream>
#include <set>

#include "lib/src/gltf/document.hpp"
#include "matbake/convert.hpp"
#include "matbake/image.hpp"
#include "matbake/material_table.hpp"
#include "matbake/scene.hpp"
#include "matbake/validate.hpp"
#include "support/files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake {
namespace {

namespace fs = std::filesystem;

const fs::path kTestdata = MATBAKE_TESTDATA_DIR;

#define REQUIRE_TESTDATA(sub)                                                               \
  if (!fs::is_directory(kTestdata / (sub))) GTEST_SKIP() << (kTestdata / (sub)).string() << \
      " is absent (it comes with the project's shared folder, not with a clone)"

// A sweep that writes every sample model again and validates it: minutes under the sanitizers (CI's
// budget), where the same models are still loaded (EveryModelLoads..., CliBake's pairs, Inspect's);
// the release build runs it.
#ifdef MATBAKE_SANITIZED
#define SWEEP_IN_RELEASE_ONLY() GTEST_SKIP() << "a sweep over every sample model: run in the release build"
#else
#define SWEEP_IN_RELEASE_ONLY() (void)0
#endif

Result<convert::Report> convert_one(const fs::path& in, const fs::path& out, std::string from = "srgb",
                              std::string to = "linear") {
  convert::Options options;
  options.from = std::move(from);
  options.to = std::move(to);
  return convert::convert_file(*convert::plan_conversion(options), in, out, options);
}

// Textures that differ once their names are set aside (TextureSettingsTest has two the same).
std::size_t distinct_textures(const gltf::Json& json) {
  std::set<gltf::Json> seen;
  for (gltf::Json t : json.value("textures", gltf::Json::array())) {
    t.erase("name");
    seen.insert(t);
  }
  return seen.size();
}

// Every .gltf and .glb of the Khronos sample models.
std::vector<fs::path> khronos_models() {
  std::vector<fs::path> files;
  for (const auto& model : fs::directory_iterator(kTestdata / "gltf")) {
    if (!model.is_directory()) continue;
    for (const char* variant : {"glTF", "glTF-Embedded", "glTF-Binary", "glTF-pbrSpecularGlossiness"}) {
      const fs::path folder = model.path() / variant;
      if (!fs::is_directory(folder)) continue;
      for (const auto& f : fs::directory_iterator(folder)) {
        const std::string ext = f.path().extension().string();
        if (ext == ".gltf" || ext == ".glb") files.push_back(f.path());
      }
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<fs::path> files_in(const fs::path& folder, const std::string& ext = "") {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder)) {
    if (e.is_regular_file() && (ext.empty() || e.path().extension() == ext)) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// A refusal is one line that names the file.
void expect_clean_error(const Result<convert::Report>& r, const fs::path& in) {
  ASSERT_FALSE(r) << in;
  EXPECT_EQ(r.error().path, in.string());
  EXPECT_FALSE(r.error().message.empty());
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos) << r.error().message;
}

TEST(PngSuite, ValidFilesConvertAndCorruptOnesAreRefused) {
  REQUIRE_TESTDATA("images/pngsuite");
  test::TempDir dir;
  int valid = 0, corrupt = 0;
  for (const fs::path& in : files_in(kTestdata / "images/pngsuite", ".png")) {
    // PngSuite names corrupt files x*.png.
    const bool is_corrupt = in.filename().string()[0] == 'x';
    auto r = convert_one(in, dir / "out.exr");
    if (is_corrupt) {
      expect_clean_error(r, in);
      ++corrupt;
    } else {
      ASSERT_TRUE(r) << r.error().to_string();
      const auto out = test::read_raw(dir / "out.exr");
      EXPECT_EQ(out.width, r->width);
      ++valid;
    }
  }
  EXPECT_GT(valid, 40);
  RecordProperty("corrupt", corrupt);
}

TEST(PngSuite, LowBitDepthsAndPalettesDecodeToTheRightValues) {
  REQUIRE_TESTDATA("images/pngsuite");
  test::TempDir dir;
  // 1-bit gray: only black and white, so only 0 and 1 after decoding.
  ASSERT_TRUE(convert_one(kTestdata / "images/pngsuite/basn0g01.png", dir / "g1.exr"));
  for (double v : test::read_raw(dir / "g1.exr").samples) EXPECT_TRUE(v == 0.0 || v == 1.0) << v;
  // 16-bit gray keeps 16-bit precision: the codes come back through a float EXR.
  convert::Options to_float;
  to_float.bits = image::SampleType::f32;
  const fs::path g16 = kTestdata / "images/pngsuite/basn0g16.png";
  ASSERT_TRUE(convert::convert_file(*convert::plan_conversion(to_float), g16, dir / "g16.exr", to_float));
  convert::Options back;
  back.from = "linear";
  back.to = "srgb";
  back.bits = image::SampleType::u16;
  ASSERT_TRUE(convert::convert_file(*convert::plan_conversion(back), dir / "g16.exr", dir / "g16.png", back));
  EXPECT_EQ(test::read_raw(dir / "g16.png").samples, test::read_raw(g16).samples);
  // A palette image arrives as RGB.
  ASSERT_TRUE(convert_one(kTestdata / "images/pngsuite/basn3p08.png", dir / "p8.exr"));
  EXPECT_EQ(test::read_raw(dir / "p8.exr").channels, 3);
}

TEST(LibpngImages, TaggedImagesConvertAndCrashersAreHandled) {
  REQUIRE_TESTDATA("images/libpng-testpngs");
  test::TempDir dir;
  for (const fs::path& in : files_in(kTestdata / "images/libpng-testpngs", ".png")) {
    auto r = convert_one(in, dir / "out.exr");
    EXPECT_TRUE(r) << r.error().to_string();
  }
  // Each crasher is either read (libpng skips a bad ancillary chunk) or refused in one line.
  for (const fs::path& in : files_in(kTestdata / "images/libpng-testpngs/crashers")) {
    auto r = convert_one(in, dir / "out.exr");
    if (!r) expect_clean_error(r, in);
  }
}

TEST(OpenExrImages, NonFiniteSamplesAreCountedExactly) {
  REQUIRE_TESTDATA("images/openexr");
  test::TempDir dir;
  for (const char* name : {"AllHalfValues.exr", "BrightRingsNanInf.exr"}) {
    const fs::path in = kTestdata / "images/openexr/TestImages" / name;
    // Count independently, through OIIO.
    std::size_t nan = 0, inf = 0, first = SIZE_MAX, index = 0;
    const auto raw = test::read_raw(in);
    for (double v : raw.samples) {
      nan += std::isnan(v), inf += std::isinf(v);
      if (!std::isfinite(v) && first == SIZE_MAX) first = index;
      ++index;
    }
    ASSERT_GT(nan + inf, 0u);
    auto r = convert_one(in, dir / "out.exr", "linear", "srgb");
    expect_clean_error(r, in);
    const std::size_t row = std::size_t(raw.width) * raw.channels;
    EXPECT_EQ(r.error().message, "contains " + std::to_string(nan) + " NaN and " + std::to_string(inf) +
                                     " Inf samples (the first at x " + std::to_string(first % row / raw.channels) +
                                     ", y " + std::to_string(first / row) + ", channel " +
                                     std::to_string(first % raw.channels) + "); matbake rejects non-finite texels");
  }
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

TEST(OpenExrImages, WideRangesAndDamagedFiles) {
  REQUIRE_TESTDATA("images/openexr");
  test::TempDir dir;
  // Negative and large values: encoded with the mirrored sRGB curve, no clamping in float; values
  // beyond the half range are refused rather than written as Inf.
  const fs::path wide = kTestdata / "images/openexr/TestImages/WideFloatRange.exr";
  auto half = convert_one(wide, dir / "wide.exr", "linear", "srgb");
  ASSERT_FALSE(half);
  EXPECT_EQ(half.error().path, (dir / "wide.exr").string());
  EXPECT_NE(half.error().message.find("exceed the half-float range"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "wide.exr"));
  convert::Options to_float;
  to_float.from = "linear";
  to_float.to = "srgb";
  to_float.bits = image::SampleType::f32;
  ASSERT_TRUE(convert::convert_file(*convert::plan_conversion(to_float), wide, dir / "wide.exr", to_float));
  const auto in = test::read_raw(wide), out = test::read_raw(dir / "wide.exr");
  ASSERT_EQ(in.samples.size(), out.samples.size());
  for (std::size_t i = 0; i < in.samples.size(); i += 97) {
    const double expected = color::encoded_from_linear(color::Transfer::srgb, in.samples[i]);
    EXPECT_NEAR(out.samples[i], expected, 1e-6 * std::abs(expected) + 1e-7) << i;
  }
  for (const fs::path& damaged : files_in(kTestdata / "images/openexr/Damaged")) {
    if (damaged.extension() == ".rst") continue;
    expect_clean_error(convert_one(damaged, dir / "out.exr"), damaged);
  }
}

// Every table entry citing physicallybased.info matches that database: F0 from its IOR or
// complex IOR (srgb-linear), recomputed here from the JSON itself.
TEST(PhysicallyBased, TableEntriesMatchTheDatabase) {
  REQUIRE_TESTDATA("materials/physicallybased");
  std::ifstream in(kTestdata / "materials/physicallybased/materials.json");
  const auto db = nlohmann::json::parse(in)["data"];
  int checked = 0;
  for (const material_table::Material& m : material_table::builtin_table()) {
    const auto quote = m.source.find("entry '");
    if (m.source.rfind("physicallybased.info", 0) != 0 || quote == std::string::npos) continue;
    const std::string name = m.source.substr(quote + 7, m.source.rfind('\'') - quote - 7);
    const auto entry = std::find_if(db.begin(), db.end(), [&](const auto& e) { return e["name"] == name; });
    ASSERT_NE(entry, db.end()) << name;
    for (int c = 0; c < 3; ++c) {
      double f0 = 0;
      if (entry->contains("ior") && (*entry)["ior"].is_number()) {
        const double n = (*entry)["ior"];
        f0 = std::pow((n - 1) / (n + 1), 2);
      } else {
        const auto& complex = (*entry)["complexIor"][0];
        ASSERT_EQ(complex["colorSpace"], "srgb-linear");
        const double n = complex["n"][c], k = complex["k"][c];
        f0 = ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
      }
      EXPECT_NEAR(m.f0[c], f0, 5e-5) << m.name;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 22);
  // The database's gold base colour is above 1 in linear red (a colour, not F0).
  const auto gold = std::find_if(db.begin(), db.end(), [](const auto& e) { return e["name"] == "Gold"; });
  EXPECT_GT((*gold)["color"][0]["color"][0].get<double>(), 1.0);
}

// Validation against every measured material of physicallybased.info, as glTF would carry it
// (base colour = its linear colour clamped to [0, 1], metallic = its metalness): nothing flagged
// but the cases docs/validate.md lists, each for the reason given there.
TEST(PhysicallyBased, ValidationFlagsOnlyTheDocumentedMaterials) {
  REQUIRE_TESTDATA("materials/physicallybased");
  std::ifstream in(kTestdata / "materials/physicallybased/materials.json");
  const auto db = nlohmann::json::parse(in)["data"];
  // Metals whose mean F0 falls in the semiconductor gap (silicon is one; anodized colours are thin
  // films); engineered extremes of diffuse albedo; transmissive materials, whose colour is a tint.
  const std::set<std::string> gap_metals = {"Silicon", "Titanium", "Titanium (Anodized)", "Aluminum (Anodized Red)"};
  const std::set<std::string> engineered = {"MIT Black", "Musou Black", "Spectralon"};
  int flagged = 0, transmissive_flagged = 0;
  for (const auto& entry : db) {
    const std::string name = entry["name"];
    material::Maps maps;
    maps.width = maps.height = 1;
    image::Image base{{1, 1, 3, {"R", "G", "B"}}, {}}, metallic{{1, 1, 1, {"Y"}}, {}};
    for (const auto& colour : entry["color"]) {
      if (colour["colorSpace"] != "srgb-linear") continue;
      for (int c = 0; c < 3; ++c) base.pixels.push_back(std::clamp(colour["color"][c].get<float>(), 0.0f, 1.0f));
    }
    metallic.pixels = {entry.value("metalness", 0.0f)};
    maps.maps.emplace(material::kBaseColor, base);
    maps.maps.emplace(material::kMetallic, metallic);
    auto report = validate::validate_maps(maps, {});
    ASSERT_TRUE(report) << name;
    std::uint8_t bits = 0;
    for (int b = 0; b < validate::kFlagCount; ++b) bits = std::uint8_t(bits | (report->flag_counts[std::size_t(b)] ? 1 << b : 0));
    const std::string flags = validate::flag_names(bits);
    flagged += !flags.empty();
    if (gap_metals.count(name)) {
      EXPECT_EQ(flags, "semiconductor_gap") << name;
    } else if (engineered.count(name)) {
      EXPECT_EQ(flags, "albedo_out_of_range") << name;
    } else if (entry.value("transmission", 0.0) > 0) {
      EXPECT_TRUE(flags.empty() || flags == "albedo_out_of_range") << name << ": " << flags;
      transmissive_flagged += !flags.empty();
    } else {
      EXPECT_EQ(flags, "") << name;
    }
  }
  EXPECT_EQ(db.size(), 110u);
  EXPECT_EQ(flagged, 4 + 3 + transmissive_flagged);
  std::printf("  %d of %zu flagged: 4 gap metals, 3 engineered, %d transmissive\n", flagged, db.size(), transmissive_flagged);
}

// Every Khronos sample model loads; counts checked where the model's README states them.
// A material rule over a folder of Khronos textures (base colour, metallic-roughness with roughness
// in G and metallic in B, normal map), through both doors: each material's textures equal `pack`'s
// with the same sources, and the Khronos scenes that use them export validator-clean.
TEST(KhronosModels, AMaterialRuleOverTheirTextures) {
  REQUIRE_TESTDATA("gltf/Cube");
  test::TempDir dir;
  fs::create_directories(dir / "textures");
  fs::create_directories(dir / "scenes");
  for (const char* model : {"Cube", "TwoSidedPlane"}) {
    const fs::path from = kTestdata / "gltf" / model / "glTF";
    fs::copy(from, dir / "scenes" / model, fs::copy_options::recursive);
    for (const auto& f : fs::directory_iterator(from)) {
      if (f.path().extension() == ".png") fs::copy_file(f.path(), dir / "textures" / f.path().filename());
    }
  }
  test::write_bytes(dir / "assets.toml", R"(validate = { enabled = false }
[material_rules.khronos]
match = "textures/{name}_BaseColor.png"
sources = { base_color = "textures/{name}_BaseColor.png", normal = "textures/{name}_Normal.png", roughness = { file = "textures/{name}_MetallicRoughness.png", channel = "g" }, metallic = { file = "textures/{name}_MetallicRoughness.png", channel = "b" } }
layout = "gltf-pbr"
[material_rules.khronos.overrides.Cube]
sources = { normal = [0.5, 0.5, 1.0] }
[scenes.cube]
input = "scenes/Cube/Cube.gltf"
[scenes.plane]
input = "scenes/TwoSidedPlane/TwoSidedPlane.gltf"
)");
  const test::RunResult dry = test::matbake({"build", (dir / "assets.toml").string(), "-n"});
  EXPECT_NE(dry.out.find("material_rules.khronos (" + (dir / "assets.toml").string() + ":2:1): 2 materials: Cube, TwoSidedPlane"),
            std::string::npos)
      << dry.out << dry.err;
  const test::RunResult built = test::matbake({"--json", "build", (dir / "assets.toml").string()});
  ASSERT_EQ(built.exit_code, 0) << built.err;
  const nlohmann::json report = nlohmann::json::parse(built.out);
  EXPECT_EQ(report["built"], 4);
  EXPECT_EQ(report["material_rules"][0]["materials"], nlohmann::json::array({"Cube", "TwoSidedPlane"}));
  for (const std::string name : {"Cube", "TwoSidedPlane"}) {
    const std::string t = (dir / "textures" / name).string();
    std::vector<std::string> args = {"pack", "--layout", "gltf-pbr", "--base-color", t + "_BaseColor.png",
                                     "--roughness", t + "_MetallicRoughness.png:g", "--metallic", t + "_MetallicRoughness.png:b",
                                     "--normal", name == "Cube" ? "0.5,0.5,1" : t + "_Normal.png",
                                     "-o", (dir / "cli" / (name + "_{texture}.png")).string()};
    const test::RunResult packed = test::matbake(args);
    ASSERT_EQ(packed.exit_code, 0) << packed.err;
    for (const char* texture : {"base_color", "orm", "normal", "emissive"}) {
      const std::string file = name + "_" + texture + ".png";
      EXPECT_TRUE(test::read_bytes(dir / "cli" / file) == test::read_bytes(dir / "out/materials" / file)) << file;
    }
  }
  for (const char* scene : {"cube.glb", "plane.glb"}) {
    MATBAKE_VALIDATE_OR_SKIP(validated, dir / "out" / scene);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
    for (const std::string& code : validated->error_and_warning_codes) {
      EXPECT_EQ(code.rfind("MESH_PRIMITIVE_GENERATED_TANGENT_SPACE ", 0), 0u) << validated->summary;
    }
  }
}

TEST(KhronosModels, EveryModelLoadsWithItsTriangleAndInstanceCounts) {
  REQUIRE_TESTDATA("gltf");
  int loaded = 0;
  for (const fs::path& file : khronos_models()) {
    auto s = scene::load_scene(file);
    ASSERT_TRUE(s) << s.error().to_string();
    ++loaded;
  }
  EXPECT_GE(loaded, 19);
  const auto load = [](const char* relative) { return *scene::load_scene(kTestdata / "gltf" / relative); };
  const scene::Scene box = load("Box/glTF-Embedded/Box.gltf");
  ASSERT_EQ(box.instances.size(), 1u);
  EXPECT_EQ(box.instances[0].triangles.size(), 12u);
  EXPECT_EQ(load("SimpleMeshes/glTF-Embedded/SimpleMeshes.gltf").instances.size(), 2u);  // one mesh, two nodes
  EXPECT_EQ(load("TriangleWithoutIndices/glTF-Embedded/TriangleWithoutIndices.gltf").instances[0].triangles.size(), 1u);
  const scene::Scene modes = load("MeshPrimitiveModes/glTF-Embedded/MeshPrimitiveModes.gltf");
  EXPECT_EQ(modes.instances.size(), 3u);  // triangles, strip, fan
  ASSERT_EQ(modes.notes.size(), 1u);
  EXPECT_EQ(modes.notes[0], "4 point or line primitives ignored");
}

// The warning codes of a report, without where they are.
std::set<std::string> codes_of(const test::ValidatorReport& report) {
  std::set<std::string> codes;
  for (const std::string& c : report.error_and_warning_codes) codes.insert(c.substr(0, c.find(' ')));
  return codes;
}

// A written file: no validator error, and no warning code its input's report did not have.
void expect_clean_as_its_input(const test::ValidatorReport& out, const std::set<std::string>& in_codes) {
  EXPECT_EQ(out.errors, 0) << out.summary;
  for (const std::string& code : codes_of(out)) EXPECT_TRUE(in_codes.contains(code)) << code << " is new in " << out.summary;
}

// bake-ao writes every sample model again, as .gltf and as .glb: the validator finds no error and
// no warning that the input did not already have (those are the models' own: e.g. the
// NormalTangent models' generated tangent space, the spec-gloss extension the validator does not
// know); nodes are kept and a mesh placed by n nodes gains n − 1 copies.
TEST(KhronosModels, BakedAoScenesStayValidatorClean) {
  REQUIRE_TESTDATA("gltf");
  SWEEP_IN_RELEASE_ONLY();
  test::TempDir dir;
  int checked = 0;
  for (const fs::path& file : khronos_models()) {
    MATBAKE_VALIDATE_OR_SKIP(in_report, file);
    ASSERT_EQ(in_report->errors, 0) << in_report->summary;
    const std::set<std::string> in_codes = codes_of(*in_report);
    const scene::Scene s = *scene::load_scene(file);
    std::set<int> meshes, nodes;
    for (const auto& inst : s.instances) meshes.insert(inst.mesh), nodes.insert(inst.node);
    const auto in = gltf::read_document(file);
    ASSERT_TRUE(in) << in.error().to_string();
    for (const char* ext : {".gltf", ".glb"}) {
      const fs::path out = dir / (file.stem().string() + "_" + file.parent_path().filename().string() + ext);
      const auto r = test::matbake({"-q", "bake-ao", file.string(), "-o", out.string(), "--samples", "8"});
      ASSERT_EQ(r.exit_code, 0) << file << ": " << r.err;
      MATBAKE_VALIDATE_OR_SKIP(out_report, out);
      expect_clean_as_its_input(*out_report, in_codes);
      const auto written = scene::load_scene(out);
      ASSERT_TRUE(written) << written.error().to_string();
      ASSERT_EQ(written->instances.size(), s.instances.size()) << out;
      for (std::size_t k = 0; k < s.instances.size(); ++k) {
        EXPECT_EQ(written->instances[k].colors.size(), s.instances[k].positions.size()) << out << " instance " << k;
      }
      const auto doc = gltf::read_document(out);
      ASSERT_TRUE(doc);
      EXPECT_EQ(doc->json["nodes"].size(), in->json["nodes"].size()) << out;
      EXPECT_EQ(doc->json["meshes"].size(), in->json["meshes"].size() + nodes.size() - meshes.size()) << out;
      ++checked;
    }
  }
  EXPECT_GE(checked, 40);
}

// bake-ao --texture on every sample model, as .gltf and .glb: each material the scene reaches whose
// primitives all have TEXCOORD_0 gets a new occlusion texture (a PNG of the asked size, its values
// in [0, 1]); the output has no validator error and no warning its input did not have. A model with
// no such material is refused in one line, and then really has none.
TEST(KhronosModels, TextureBakedScenesStayValidatorClean) {
  REQUIRE_TESTDATA("gltf");
  SWEEP_IN_RELEASE_ONLY();
  test::TempDir dir;
  int baked = 0;
  for (const fs::path& file : khronos_models()) {
    MATBAKE_VALIDATE_OR_SKIP(in_report, file);
    const std::set<std::string> in_codes = codes_of(*in_report);
    const auto in = gltf::read_document(file);
    ASSERT_TRUE(in);
    for (const char* ext : {".gltf", ".glb"}) {
      const fs::path out = dir / (file.stem().string() + "_" + file.parent_path().filename().string() + "_tex" + ext);
      const auto r = test::matbake({"--json", "bake-ao", file.string(), "-o", out.string(), "--texture", "32x16",
                                    "--samples", "4"});
      if (r.exit_code == 1) {
        EXPECT_NE(r.err.find("no material the scene reaches can hold an occlusion texture"), std::string::npos) << r.err;
        const scene::Scene s = *scene::load_scene(file, {.texcoords = true});
        for (const auto& inst : s.instances) EXPECT_TRUE(inst.material < 0 || inst.texcoords.empty()) << file;
        EXPECT_FALSE(fs::exists(out));
        continue;
      }
      ASSERT_EQ(r.exit_code, 0) << file << ": " << r.err;
      MATBAKE_VALIDATE_OR_SKIP(out_report, out);
      expect_clean_as_its_input(*out_report, in_codes);
      const auto report = nlohmann::json::parse(r.out);
      ASSERT_FALSE(report["textures"].empty()) << file;
      const auto doc = gltf::read_document(out);
      ASSERT_TRUE(doc);
      for (const auto& t : report["textures"]) {
        const auto& material = doc->json["materials"][t["material"].get<std::size_t>()];
        const std::size_t texture = material["occlusionTexture"]["index"].get<std::size_t>();
        const std::size_t source = doc->json["textures"][texture]["source"].get<std::size_t>();
        EXPECT_GE(source, in->json["images"].size()) << out << ": a new image";
        const auto bytes = gltf::image_bytes(*doc, source);
        ASSERT_TRUE(bytes);
        const auto img = image::decode_image({reinterpret_cast<const unsigned char*>(bytes->data()), bytes->size()},
                                             "occlusion.png", color::Transfer::linear);
        ASSERT_TRUE(img) << img.error().to_string();
        EXPECT_EQ(img->width, 32);
        EXPECT_EQ(img->height, 16);
        for (float v : img->pixels) ASSERT_TRUE(v >= 0 && v <= 1) << out;
      }
      ++baked;
    }
  }
  EXPECT_GE(baked, 24);
}

// export writes every sample model again: validator-clean with no warning its input did not have,
// node, mesh and material counts kept, and with --no-orm the texture count too (ORM packing may
// join two textures into one, so by default the count can only fall). The spec-gloss models come
// out as metal-rough, with KHR_materials_specular where their dielectric F0 is not 0.04.
TEST(KhronosModels, ExportedScenesStayValidatorCleanWithTheirCounts) {
  REQUIRE_TESTDATA("gltf");
  SWEEP_IN_RELEASE_ONLY();
  test::TempDir dir;
  int checked = 0, converted = 0;
  const auto count = [](const gltf::Json& json, const char* key) { return json.contains(key) ? json[key].size() : 0; };
  for (const fs::path& file : khronos_models()) {
    MATBAKE_VALIDATE_OR_SKIP(in_report, file);
    const std::set<std::string> in_codes = codes_of(*in_report);
    const auto in = gltf::read_document(file);
    ASSERT_TRUE(in) << in.error().to_string();
    const bool spec_gloss = in->json.contains("extensionsUsed") &&
                            in->json["extensionsUsed"].dump().find("pbrSpecularGlossiness") != std::string::npos;
    for (const bool orm : {true, false}) {
      const fs::path out = dir / (file.stem().string() + "_" + file.parent_path().filename().string() + (orm ? "_orm.glb" : ".gltf"));
      std::vector<std::string> args = {"--json", "export", file.string(), "-o", out.string()};
      if (!orm) args.push_back("--no-orm");
      const auto r = test::matbake(args);
      ASSERT_EQ(r.exit_code, 0) << file << ": " << r.err;
      MATBAKE_VALIDATE_OR_SKIP(out_report, out);
      expect_clean_as_its_input(*out_report, in_codes);
      const auto doc = gltf::read_document(out);
      ASSERT_TRUE(doc) << doc.error().to_string();
      for (const char* key : {"nodes", "meshes", "materials"}) EXPECT_EQ(count(doc->json, key), count(in->json, key)) << out << " " << key;
      if (orm) {
        EXPECT_LE(count(doc->json, "textures"), count(in->json, "textures") + (spec_gloss ? count(in->json, "materials") : 0)) << out;
      } else if (!spec_gloss) {
        EXPECT_EQ(count(doc->json, "textures"), distinct_textures(in->json)) << out;  // duplicates stored once
      }
      if (spec_gloss) {
        EXPECT_EQ(doc->json["materials"].dump().find("pbrSpecularGlossiness"), std::string::npos) << out;
        EXPECT_EQ(doc->json.value("extensionsUsed", gltf::Json::array()).dump().find("pbrSpecularGlossiness"), std::string::npos);
        const nlohmann::json report = nlohmann::json::parse(r.out);
        bool any = false;
        for (const auto& m : report["materials"]) any = any || m.contains("errors");
        EXPECT_TRUE(any) << out << ": no conversion error reported";
        // The bottle's dielectric F0 (mean 0.043) is not core glTF's 0.04.
        if (file.filename() == "SpecGlossVsMetalRough.gltf") {
          EXPECT_NE(doc->json.value("extensionsUsed", gltf::Json::array()).dump().find("KHR_materials_specular"), std::string::npos);
        }
        converted += orm;
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 40);
  EXPECT_GE(converted, 2);  // BoxTextured's spec-gloss variant and SpecGlossVsMetalRough
}

// Issue "One request layer": every material of every sample replaced, (b) by a Schüler pair and
// (c) by metal-rough maps, comes out validator-clean, with no warning its input did not have and no
// trace of what it replaced. Textures (4×4) where every primitive drawing the material has
// TEXCOORD_0, else 1×1 files (factors).
TEST(KhronosModels, EveryMaterialReplacedStaysValidatorClean) {
  REQUIRE_TESTDATA("gltf");
  SWEEP_IN_RELEASE_ONLY();
  test::TempDir dir;
  const auto noise = [&](const char* name, int size, int channels, int lo, int hi) {
    std::vector<double> samples;
    for (int i = 0; i < size * size * channels; ++i) samples.push_back(lo + (i * 37) % (hi - lo + 1));
    test::write_raw(dir / name, size, size, channels, "uint8", samples);
    return (dir / name).string();
  };
  struct Replacement {
    std::string kind, textured, constant;  // the --material value after "INDEX="
  };
  const std::vector<Replacement> replacements = {
      {"schuler", noise("a4.png", 4, 4, 0, 255) + "," + noise("b4.png", 4, 4, 5, 250),
       noise("a1.png", 1, 4, 120, 200) + "," + noise("b1.png", 1, 4, 10, 40)},
      {"metal-rough", "gltf-metal-rough:" + noise("base4.png", 4, 4, 0, 255) + "," + noise("mr4.png", 4, 3, 0, 255),
       "gltf-metal-rough:" + noise("base1.png", 1, 4, 50, 250) + "," + noise("mr1.png", 1, 3, 0, 255)}};
  int checked = 0;
  for (const fs::path& file : khronos_models()) {
    MATBAKE_VALIDATE_OR_SKIP(in_report, file);
    const std::set<std::string> in_codes = codes_of(*in_report);
    const auto in = gltf::read_document(file);
    ASSERT_TRUE(in) << in.error().to_string();
    if (!in->json.contains("materials")) continue;
    // Materials drawn by a primitive without TEXCOORD_0 take constants.
    std::set<int> without_uv;
    for (const auto& mesh : in->json.value("meshes", gltf::Json::array())) {
      for (const auto& p : mesh["primitives"]) {
        if (p.contains("material") && !p["attributes"].contains("TEXCOORD_0")) without_uv.insert(p["material"].get<int>());
      }
    }
    for (const Replacement& r : replacements) {
      const fs::path out = dir / (file.stem().string() + "_" + file.parent_path().filename().string() + "_" + r.kind + ".glb");
      std::vector<std::string> args = {"export", file.string(), "-o", out.string()};
      for (std::size_t m = 0; m < in->json["materials"].size(); ++m) {
        args.push_back("--material");
        args.push_back(std::to_string(m) + "=" + (without_uv.contains(int(m)) ? r.constant : r.textured));
      }
      const auto run = test::matbake(args);
      ASSERT_EQ(run.exit_code, 0) << file << " " << r.kind << ": " << run.err;
      MATBAKE_VALIDATE_OR_SKIP(out_report, out);
      expect_clean_as_its_input(*out_report, in_codes);
      const auto doc = gltf::read_document(out);
      ASSERT_TRUE(doc) << doc.error().to_string();
      // (Not the whole JSON: images are named after the output file, whose name may hold it.)
      EXPECT_EQ(doc->json["materials"].dump().find("pbrSpecularGlossiness"), std::string::npos) << out;
      EXPECT_EQ(doc->json.value("extensionsUsed", gltf::Json::array()).dump().find("pbrSpecularGlossiness"), std::string::npos) << out;
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);
}

}  // namespace
}  // namespace matbake
