// `matbake export` end to end on scenes written here: texel values of converted textures against the
// exact cases of the workflow (pure dielectric at F0 0.04: base = Kd; pure metal: base = Ks), factors
// and KHR_materials_specular for constant materials, ORM packing of a texture shared by two
// materials (made once), alpha modes from the mask, pruning and its report, AO, byte-identical
// runs, and bad input. Every file written passes the Khronos glTF-Validator.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <set>

#include "lib/src/gltf/document.hpp"
#include "matbake/ao.hpp"
#include "matbake/color.hpp"
#include "matbake/version.hpp"
#include "matbake/workflow.hpp"
#include "support/build_kind.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/png_chunks.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A quad with texture coordinates drawn with material 0 by node 0 (the scene), and a second quad
// with material 1 placed only by node 1, which is not in the scene.
GltfBuilder quad_scene(const json& materials) {
  GltfBuilder b;
  const int positions = b.add_vec3({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
  const int uvs = b.add_floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  const int indices = b.add_indices({0, 1, 2, 0, 2, 3});
  for (int m = 0; m < 2; ++m) {
    b.doc["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", positions}, {"TEXCOORD_0", uvs}}},
                                                {"indices", indices}, {"material", m}}}}});
  }
  b.add_node({{"mesh", 0}});
  b.add_node({{"mesh", 1}, {"translation", {5, 0, 0}}});
  b.doc["materials"] = materials;
  return b;
}

// The pixels of texture `t` as stored (codes).
RawImage texture_pixels(const gltf::Document& doc, int texture, const fs::path& scratch) {
  const int image = doc.json["textures"][std::size_t(texture)]["source"];
  auto bytes = gltf::image_bytes(doc, std::size_t(image));
  EXPECT_TRUE(bytes);
  write_bytes(scratch, *bytes);
  return read_raw(scratch);
}

json export_json(const std::vector<std::string>& args) {
  std::vector<std::string> all = {"--json", "export"};
  all.insert(all.end(), args.begin(), args.end());
  const RunResult r = matbake(all);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.exit_code == 0 ? json::parse(r.out) : json();
}

void expect_validator_clean(const fs::path& file) {
  MATBAKE_VALIDATE_OR_SKIP(report, file);
  EXPECT_EQ(report->errors, 0) << report->summary;
  EXPECT_EQ(report->warnings, 0) << report->summary;
}

double code_to_linear(double code) { return color::linear_from_encoded(color::Transfer::srgb, code / 255.0); }

TEST(CliExport, SpecGlossTexturesConvertTexelByTexel) {
  TempDir dir;
  // Texel 0: a dielectric at F0 0.0395 (code 56: within 0.001 of 0.04, the exact case base = Kd);
  // texel 1: a pure metal (Kd black: base = Ks, metallic 1).
  write_raw(dir / "diffuse.png", 2, 1, 4, "uint8", {200, 100, 50, 255, 0, 0, 0, 255});
  write_raw(dir / "specgloss.png", 2, 1, 4, "uint8", {56, 56, 56, 128, 255, 200, 87, 191});
  GltfBuilder b = quad_scene(json::array(
      {{{"name", "Painted"},
        {"extensions", {{"KHR_materials_pbrSpecularGlossiness",
                         {{"diffuseTexture", {{"index", 0}}}, {"specularGlossinessTexture", {{"index", 1}}}}}}}},
       {{"name", "Unused"}}}));
  b.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
  b.doc["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 1}, {"sampler", 0}}};
  b.doc["samplers"] = {{{"magFilter", 9728}, {"wrapS", 33071}}};
  b.doc["images"] = {{{"uri", "diffuse.png"}}, {{"uri", "specgloss.png"}}};
  b.write(dir / "in.gltf", {0});
  fs::create_directories(dir / "out");
  const json report = export_json({(dir / "in.gltf").string(), "-o", (dir / "out" / "scene.gltf").string()});
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["materials"][0]["action"], "converted from KHR_materials_pbrSpecularGlossiness");
  EXPECT_EQ(report["images_decoded"], 2);

  const gltf::Document out = read_output(dir / "out" / "scene.gltf");
  EXPECT_FALSE(out.json.contains("extensionsUsed"));
  ASSERT_EQ(out.json["materials"].size(), 1u);
  const auto& pbr = out.json["materials"][0]["pbrMetallicRoughness"];
  EXPECT_FALSE(out.json["materials"][0].contains("extensions"));  // F0 0.0395: core glTF's 0.04 is close enough
  ASSERT_EQ(out.json["samplers"].size(), 1u);
  EXPECT_EQ(out.json["textures"][pbr["baseColorTexture"]["index"].get<std::size_t>()]["sampler"], 0);
  const RawImage base = texture_pixels(out, pbr["baseColorTexture"]["index"], dir / "base.png");
  const RawImage mr = texture_pixels(out, pbr["metallicRoughnessTexture"]["index"], dir / "mr.png");
  ASSERT_EQ(base.channels, 4);
  EXPECT_EQ(base.samples, (std::vector<double>{200, 100, 50, 255, 255, 200, 87, 255}));
  ASSERT_EQ(mr.channels, 3);
  const auto rough = [](double gloss, double f0) {
    return std::round(255 * workflow::roughness_from_gloss(gloss, workflow::RoughnessMapping::fitted, f0));
  };
  const double metal_f0 = (code_to_linear(255) + code_to_linear(200) + code_to_linear(87)) / 3;
  EXPECT_NEAR(mr.samples[1], rough(128 / 255.0, code_to_linear(56)), 1);
  EXPECT_EQ(mr.samples[2], 0);  // metallic
  EXPECT_NEAR(mr.samples[4], rough(191 / 255.0, metal_f0), 1);
  EXPECT_EQ(mr.samples[5], 255);
  expect_validator_clean(dir / "out" / "scene.gltf");
}

// Issue "One request layer": a spec-gloss material replaced by given maps kept its old extension
// object (and the textures it names) while extensionsUsed dropped it: UNDECLARED_EXTENSION.
TEST(CliExport, ReplacedSpecGlossMaterialsComeOutClean) {
  TempDir dir;
  write_raw(dir / "diffuse.png", 2, 1, 4, "uint8", {200, 100, 50, 255, 0, 0, 0, 255});
  write_raw(dir / "specgloss.png", 2, 1, 4, "uint8", {56, 56, 56, 128, 255, 200, 87, 191});
  write_raw(dir / "a.png", 2, 1, 4, "uint8", {20, 120, 220, 255, 40, 50, 60, 255});
  write_raw(dir / "b.png", 2, 1, 4, "uint8", {30, 30, 30, 100, 40, 40, 40, 200});  // F0 ≈ 0.013, 0.021
  GltfBuilder b = quad_scene(json::array(
      {{{"name", "Painted"},
        {"extensions", {{"KHR_materials_pbrSpecularGlossiness",
                         {{"diffuseTexture", {{"index", 0}}}, {"specularGlossinessTexture", {{"index", 1}}}}},
                        {"KHR_materials_ior", {{"ior", 1.3}}}}}},
       {{"name", "Unused"}}}));
  b.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness", "KHR_materials_ior"};
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  b.doc["images"] = {{{"uri", "diffuse.png"}}, {{"uri", "specgloss.png"}}};
  b.write(dir / "in.gltf", {0});
  fs::create_directories(dir / "out");
  const json report = export_json({(dir / "in.gltf").string(), "-o", (dir / "out" / "scene.gltf").string(), "--material",
                                   "Painted=" + (dir / "a.png").string() + "," + (dir / "b.png").string()});
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["materials"][0]["action"], "from Schüler maps");
  const gltf::Document out = read_output(dir / "out" / "scene.gltf");
  const json material = json::parse(out.json["materials"][0].dump());
  // The maps' F0 (below 0.04) is said by KHR_materials_specular; the old IOR and spec-gloss are gone.
  EXPECT_EQ(material["extensions"].size(), 1u) << material.dump();
  EXPECT_TRUE(material["extensions"].contains("KHR_materials_specular"));
  EXPECT_EQ(out.json["extensionsUsed"], json({"KHR_materials_specular"}));
  EXPECT_EQ(out.json["images"].size(), 2u);  // the new base colour and metallic-roughness: the old ones pruned
  expect_validator_clean(dir / "out" / "scene.gltf");
}

TEST(CliExport, ConstantMaterialsBecomeFactorsAndCarryTheirF0) {
  TempDir dir;
  // Water-like: F0 0.02, which core glTF cannot say; KHR_materials_specular's factor is 0.02 / 0.04.
  // Two materials with the same block: the second reuses the first's conversion.
  const json water = {{"extensions", {{"KHR_materials_pbrSpecularGlossiness",
                                       {{"diffuseFactor", {0.3, 0.4, 0.5, 1}}, {"specularFactor", {0.02, 0.02, 0.02}},
                                        {"glossinessFactor", 0.75}}}}}};
  GltfBuilder b = quad_scene(json::array({water, water}));
  b.write(dir / "in.gltf", {0, 1});
  const json report = export_json({(dir / "in.gltf").string(), "-o", (dir / "out.glb").string()});
  ASSERT_FALSE(report.is_null());
  const gltf::Document out = read_output(dir / "out.glb");
  const auto& material = out.json["materials"][0];
  const auto expected = workflow::metal_rough_from_spec_gloss({{0.3, 0.4, 0.5}, {0.02, 0.02, 0.02}, 0.75},
                                                               workflow::RoughnessMapping::fitted);
  const auto& pbr = material["pbrMetallicRoughness"];
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(pbr["baseColorFactor"][c].get<double>(), expected.base[c], 1e-6);
  EXPECT_NEAR(pbr["metallicFactor"].get<double>(), expected.metallic, 1e-6);
  EXPECT_NEAR(pbr["roughnessFactor"].get<double>(), expected.roughness, 1e-6);
  EXPECT_FALSE(pbr.contains("baseColorTexture"));
  EXPECT_NEAR(material["extensions"]["KHR_materials_specular"]["specularColorFactor"][0].get<double>(), 0.5, 1e-6);
  EXPECT_EQ(out.json["extensionsUsed"], json::array({"KHR_materials_specular"}));
  EXPECT_NEAR(report["materials"][0]["dielectric_f0"]["mean_f0"].get<double>(), 0.02, 1e-7);
  EXPECT_EQ(out.json["materials"][1], out.json["materials"][0]);
  EXPECT_EQ(report["materials"][1]["action"],
            "converted from KHR_materials_pbrSpecularGlossiness (same as an earlier material: its textures reused)");
  EXPECT_EQ(report["materials"][1]["KHR_materials_specular"], report["materials"][0]["KHR_materials_specular"]);
  expect_validator_clean(dir / "out.glb");
  // The same F0 as an IOR: ((n − 1)/(n + 1))² = 0.02.
  ASSERT_FALSE(export_json({(dir / "in.gltf").string(), "-o", (dir / "ior.glb").string(), "--dielectric-f0", "ior"}).is_null());
  const gltf::Document ior = read_output(dir / "ior.glb");
  const double n = ior.json["materials"][0]["extensions"]["KHR_materials_ior"]["ior"];
  EXPECT_NEAR(std::pow((n - 1) / (n + 1), 2), 0.02, 1e-7);
  EXPECT_FALSE(ior.json["materials"][0]["extensions"].contains("KHR_materials_specular"));
  expect_validator_clean(dir / "ior.glb");
}

TEST(CliExport, OcclusionAndMetalRoughPackOnceIntoOrm) {
  TempDir dir;
  write_raw(dir / "occlusion.png", 2, 1, 1, "uint8", {10, 240});
  write_raw(dir / "mr.png", 2, 1, 3, "uint8", {0, 30, 200, 0, 90, 5});
  const json metal_rough = {{"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", 1}}}}},
                            {"occlusionTexture", {{"index", 0}, {"strength", 0.8}}}};
  json first = metal_rough, second = metal_rough;
  first["name"] = "A";
  second["name"] = "B";
  GltfBuilder b = quad_scene(json::array({first, second}));
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  b.doc["images"] = {{{"uri", "occlusion.png"}}, {{"uri", "mr.png"}}};
  b.write(dir / "in.gltf", {0, 1});  // both quads in the scene: both materials
  const json report = export_json({(dir / "in.gltf").string(), "-o", (dir / "orm.glb").string()});
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["textures_made"], 1);
  EXPECT_EQ(report["images_decoded"], 2);
  const gltf::Document out = read_output(dir / "orm.glb");
  ASSERT_EQ(out.json["textures"].size(), 1u);  // the two originals are gone, replaced by one
  for (const auto& m : out.json["materials"]) {
    EXPECT_EQ(m["occlusionTexture"]["index"], 0);
    EXPECT_EQ(m["occlusionTexture"]["strength"], 0.8);
    EXPECT_EQ(m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"], 0);
  }
  const RawImage orm = texture_pixels(out, 0, dir / "orm.png");
  EXPECT_EQ(orm.samples, (std::vector<double>{10, 30, 200, 240, 90, 5}));
  expect_validator_clean(dir / "orm.glb");
  // --no-orm keeps them apart.
  const json kept = export_json({(dir / "in.gltf").string(), "-o", (dir / "apart.glb").string(), "--no-orm"});
  EXPECT_EQ(read_output(dir / "apart.glb").json["textures"].size(), 2u);
}

TEST(CliExport, SchulerPairsWithMasksAndTheirAlphaModes) {
  TempDir dir;
  // Pair A: Kd + mask; pair B: grey Ks at code 56 (F0 0.0395: a pure dielectric, base = Kd) + gloss.
  // A binary mask gives MASK; a partial one BLEND.
  write_raw(dir / "a_mask.png", 2, 1, 4, "uint8", {180, 120, 60, 255, 180, 120, 60, 0});
  write_raw(dir / "a_blend.png", 2, 1, 4, "uint8", {180, 120, 60, 255, 180, 120, 60, 128});
  write_raw(dir / "b.png", 2, 1, 4, "uint8", {56, 56, 56, 200, 56, 56, 56, 200});
  GltfBuilder b = quad_scene(json::array({{{"name", "Leaf"}}, {{"name", "Glass"}}}));
  b.write(dir / "in.gltf", {0, 1});
  const std::string in = (dir / "in.gltf").string();
  const json report = export_json({in, "-o", (dir / "out.gltf").string(), "--material",
                                   "Leaf=" + (dir / "a_mask.png").string() + "," + (dir / "b.png").string(),
                                   "--material", "1=schuler:" + (dir / "a_blend.png").string() + "," + (dir / "b.png").string()});
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["materials"][0]["action"], "from Schüler maps");
  const gltf::Document out = read_output(dir / "out.gltf");
  EXPECT_EQ(out.json["materials"][0]["alphaMode"], "MASK");
  EXPECT_EQ(out.json["materials"][0]["alphaCutoff"], 0.5);
  EXPECT_EQ(out.json["materials"][1]["alphaMode"], "BLEND");
  const RawImage base = texture_pixels(out, out.json["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"]["index"],
                                       dir / "base.png");
  EXPECT_EQ(base.samples, (std::vector<double>{180, 120, 60, 255, 180, 120, 60, 128}));  // Kd kept, mask in alpha
  expect_validator_clean(dir / "out.gltf");
}

TEST(CliExport, OnlyWhatTheSceneReachesAndTheSameBytesEveryTime) {
  TempDir dir;
  write_raw(dir / "unused.png", 1, 1, 3, "uint8", {1, 2, 3});
  GltfBuilder b = quad_scene(json::array({{{"name", "Used"}}, {{"name", "Unused"},
                                            {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}));
  b.doc["textures"] = {{{"source", 0}}};
  b.doc["images"] = {{{"uri", "unused.png"}}};
  b.write(dir / "in.gltf", {0});
  const json report = export_json({(dir / "in.gltf").string(), "-o", (dir / "a.glb").string(), "--ao-samples", "16"});
  ASSERT_FALSE(report.is_null());
  const std::vector<std::string> skipped = report["skipped"];
  for (const char* what : {"mesh 1: not reachable from the default scene",
                           "material 1 'Unused': not reachable from the default scene",
                           "texture 0: not reachable from the default scene", "image 0: not reachable from the default scene"}) {
    EXPECT_NE(std::find(skipped.begin(), skipped.end(), what), skipped.end()) << what;
  }
  EXPECT_EQ(report["ao_rays"], 4 * 16);
  const gltf::Document out = read_output(dir / "a.glb");
  EXPECT_EQ(out.json["nodes"].size(), 2u);
  EXPECT_FALSE(out.json["nodes"][1].contains("mesh"));
  EXPECT_EQ(out.json["meshes"].size(), 1u);
  EXPECT_EQ(out.json["materials"].size(), 1u);
  EXPECT_FALSE(out.json.contains("textures"));
  const auto& attributes = out.json["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_EQ(attributes.size(), 3u);  // POSITION, TEXCOORD_0 as they were, and COLOR_0
  for (const char* a : {"POSITION", "TEXCOORD_0", "COLOR_0"}) {
    EXPECT_EQ(out.json["accessors"][attributes[a].get<std::size_t>()]["count"], 4) << a;
  }
  expect_validator_clean(dir / "a.glb");
  ASSERT_EQ(matbake({"-q", "export", (dir / "in.gltf").string(), "-o", (dir / "b.glb").string(), "--ao-samples", "16"}).exit_code, 0);
  EXPECT_EQ(read_bytes(dir / "a.glb"), read_bytes(dir / "b.glb"));
}

// Identical images are stored once and the textures that then match are one (WaterBottle's normal
// map was stored twice); --json's texture indices are the written file's, each naming its image.
TEST(CliExport, IdenticalImagesAreStoredOnceAndTheReportUsesTheFilesIndices) {
  TempDir dir;
  std::vector<double> colour, normal;
  for (int i = 0; i < 64; ++i) {
    colour.insert(colour.end(), {double(i * 3), double(255 - i * 2), 40});
    normal.insert(normal.end(), {128, 128, 255});
  }
  write_raw(dir / "a.png", 8, 8, 3, "uint8", colour);
  write_raw(dir / "b.png", 8, 8, 3, "uint8", colour);  // the same bytes under another name
  write_raw(dir / "n.png", 8, 8, 3, "uint8", normal);
  GltfBuilder b = quad_scene(json::array({{{"name", "Lamp"},
                                           {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}},
                                           {"emissiveTexture", {{"index", 0}}},
                                           {"emissiveFactor", {1, 1, 1}},
                                           {"occlusionTexture", {{"index", 2}}}},
                                          {{"name", "Unplaced"}}}));
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}, {{"source", 2}}};
  b.doc["images"] = {{{"uri", "a.png"}}, {{"uri", "b.png"}}, {{"uri", "n.png"}}};
  b.write(dir / "in.gltf", {0});

  // As it is, and with the colour textures resized (delivery's report).
  for (const std::vector<std::string>& extra : {std::vector<std::string>{}, std::vector<std::string>{"--colour-max-size", "4"}}) {
    const fs::path out = dir / (extra.empty() ? "plain/out.gltf" : "resized/out.gltf");
    std::vector<std::string> args = {(dir / "in.gltf").string(), "-o", out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const json report = export_json(args);
    ASSERT_FALSE(report.is_null());
    const gltf::Document doc = read_output(out);
    SCOPED_TRACE(out.string());
    EXPECT_EQ(doc.json["images"].size(), 2u);
    EXPECT_EQ(doc.json["textures"].size(), 2u);
    const json& lamp = doc.json["materials"][0];
    EXPECT_EQ(lamp["pbrMetallicRoughness"]["baseColorTexture"]["index"], lamp["emissiveTexture"]["index"]);
    for (const json& t : report["textures"]) {
      ASSERT_LT(t["texture"].get<std::size_t>(), doc.json["textures"].size());
      const json& texture = doc.json["textures"][t["texture"].get<std::size_t>()];
      if (!t["file"].get<std::string>().empty()) {
        EXPECT_EQ(doc.json["images"][texture["source"].get<std::size_t>()]["uri"], t["file"]);
      }
      EXPECT_EQ(t["materials"], json::array({0}));
    }
    EXPECT_EQ(report["textures"].size(), extra.empty() ? 0u : 2u);  // the colour texture once, the occlusion map
    expect_validator_clean(out);
  }
}

// Textures delivery makes alike from images of other bytes (one colour as an 8-bit and a 16-bit
// PNG, as TextureEncodingTest has it) are stored once, and the report names that texture with every
// material that uses it (it named the first material's alone).
TEST(CliExport, TexturesMadeAlikeAreOneReportWithEveryMaterial) {
  TempDir dir;
  std::vector<double> colour, deep;
  for (int i = 0; i < 64; ++i) colour.insert(colour.end(), {double(i * 3), double(255 - i * 2), 40});
  for (double v : colour) deep.push_back(v * 257);
  write_raw(dir / "a8.png", 8, 8, 3, "uint8", colour);
  write_raw(dir / "a16.png", 8, 8, 3, "uint16", deep);
  GltfBuilder b = quad_scene(json::array({{{"name", "A"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}},
                                          {{"name", "B"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}}}));
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  b.doc["images"] = {{{"uri", "a8.png"}}, {{"uri", "a16.png"}}};
  b.write(dir / "in.gltf", {0, 1});
  const json report = export_json({(dir / "in.gltf").string(), "-o", (dir / "out.gltf").string(), "--colour-max-size", "4"});
  ASSERT_FALSE(report.is_null());
  const gltf::Document doc = read_output(dir / "out.gltf");
  EXPECT_EQ(doc.json["textures"].size(), 1u);
  ASSERT_EQ(report["textures"].size(), 1u) << report["textures"].dump();
  EXPECT_EQ(report["textures"][0]["materials"], json::array({0, 1}));
}

// Made textures are named from their material and slot (its name made safe for a file — "Lamp
// Shade!" is Lamp_Shade — not its index), files, images and textures alike; a texture delivery rewrites loses its stale name.
TEST(CliExport, MadeTexturesAreNamedFromTheirMaterialAndSlot) {
  TempDir dir;
  std::vector<double> base, mr;
  for (int i = 0; i < 16; ++i) base.insert(base.end(), {double(i * 16), 90, 200}), mr.insert(mr.end(), {0, double(i * 16), 0});
  write_raw(dir / "base.png", 4, 4, 3, "uint8", base);
  write_raw(dir / "mr.png", 4, 4, 3, "uint8", mr);
  GltfBuilder b = quad_scene(json::array({{{"name", "Lamp Shade!"}}, {{"name", "Unplaced"}}}));
  b.write(dir / "in.gltf", {0});
  const RunResult r = matbake({"-q", "export", (dir / "in.gltf").string(), "-o", (dir / "out" / "room.gltf").string(),
                               "--material", "Lamp Shade!=gltf-metal-rough:" + (dir / "base.png").string() + "," + (dir / "mr.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const gltf::Document doc = read_output(dir / "out" / "room.gltf");
  std::set<std::string> images, textures;
  for (const auto& i : doc.json["images"]) images.insert(i["name"].get<std::string>() + "=" + i["uri"].get<std::string>());
  for (const auto& t : doc.json["textures"]) textures.insert(t["name"].get<std::string>());
  EXPECT_EQ(images, (std::set<std::string>{"room_Lamp_Shade_base_color=room_Lamp_Shade_base_color.png",
                                           "room_Lamp_Shade_metallic_roughness=room_Lamp_Shade_metallic_roughness.png"}));
  EXPECT_EQ(textures, (std::set<std::string>{"room_Lamp_Shade_base_color", "room_Lamp_Shade_metallic_roughness"}));
  EXPECT_TRUE(fs::exists(dir / "out" / "room_Lamp_Shade_base_color.png"));
}

// matbake wrote the file, so asset.generator says so; what made the input is kept beside it (and
// not overwritten when matbake's output is exported again).
TEST(CliExport, TheGeneratorIsMatbakeAndTheInputsIsKept) {
  TempDir dir;
  GltfBuilder b = quad_scene(json::array({{{"name", "Plain"}}, {{"name", "Unplaced"}}}));
  b.doc["asset"]["generator"] = "babylon.js glTF exporter for 3dsmax";
  b.write(dir / "in.gltf", {0});
  const std::string mine = std::string("matbake ") + version;
  ASSERT_EQ(matbake({"-q", "export", (dir / "in.gltf").string(), "-o", (dir / "a.gltf").string()}).exit_code, 0);
  ASSERT_EQ(matbake({"-q", "export", (dir / "a.gltf").string(), "-o", (dir / "b.glb").string()}).exit_code, 0);
  for (const char* out : {"a.gltf", "b.glb"}) {
    const json asset = read_output(dir / out).json["asset"];
    EXPECT_EQ(asset["version"], "2.0") << out;
    EXPECT_EQ(asset["generator"], mine) << out;
    EXPECT_EQ(asset["extras"]["source_generator"], "babylon.js glTF exporter for 3dsmax") << out;
  }
  expect_validator_clean(dir / "b.glb");
}

// Issue "One request layer": export decoded and encoded through a private folder under $TMPDIR
// (left behind by an interrupt). Now everything happens in memory: an unusable $TMPDIR changes nothing.
TEST(CliExport, NoTemporaryFolderOutsideTheOutput) {
  TempDir dir;
  write_raw(dir / "a.png", 2, 1, 4, "uint8", {20, 120, 220, 255, 40, 50, 60, 128});
  write_raw(dir / "b.png", 2, 1, 4, "uint8", {30, 30, 30, 100, 250, 200, 40, 200});
  quad_scene(json::array({{{"name", "M"}}, {{"name", "N"}}})).write(dir / "in.gltf", {0});
  fs::create_directories(dir / "out");
  write_bytes(dir / "not-a-folder", "");
  const RunResult r = matbake({"export", (dir / "in.gltf").string(), "-o", (dir / "out" / "scene.glb").string(),
                               "--material", "M=" + (dir / "a.png").string() + "," + (dir / "b.png").string()},
                              {"TMPDIR=" + (dir / "not-a-folder").string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(list_folder(dir / "out"), std::vector<std::string>{"scene.glb"});
}

// AO is baked when any --ao-* option is given (as a manifest's ao table turns it on), and with none
// of them not at all; --ao-samples 0, once "no AO", is refused naming its range.
TEST(CliExport, AnyAoOptionBakesAndNoneBakesNothing) {
  TempDir dir;
  quad_scene(json::array({{{"name", "M"}}, {{"name", "N"}}})).write(dir / "in.gltf", {0});
  const json plain = export_json({(dir / "in.gltf").string(), "-o", (dir / "plain.glb").string()});
  ASSERT_FALSE(plain.is_null());
  EXPECT_EQ(plain["ao_rays"], 0);
  EXPECT_FALSE(read_output(dir / "plain.glb").json["meshes"][0]["primitives"][0]["attributes"].contains("COLOR_0"));
  const json baked = export_json({(dir / "in.gltf").string(), "-o", (dir / "baked.glb").string(), "--ao-tau", "2"});
  ASSERT_FALSE(baked.is_null());
  EXPECT_EQ(baked["ao_rays"], 4 * ao::Options{}.samples);  // the quad's 4 vertices at the default count
  EXPECT_TRUE(read_output(dir / "baked.glb").json["meshes"][0]["primitives"][0]["attributes"].contains("COLOR_0"));
  const RunResult zero = matbake({"export", (dir / "in.gltf").string(), "-o", (dir / "zero.glb").string(), "--ao-samples", "0"});
  EXPECT_EQ(zero.exit_code, 2);
  expect_one_error_line(zero, "", "--ao-samples: '0': 1 to 1048576");
  EXPECT_FALSE(fs::exists(dir / "zero.glb"));
}

// 100 000 nested nodes (a hostile or generated file): export and its AO walk them without
// recursion; the mesh at the bottom gets its colours. 10 000 in the sanitizer build (as SceneLoad's).
TEST(CliExport, DeepNodeChainExportsWithAo) {
  TempDir dir;
  GltfBuilder b = quad_scene(json::array({{{"name", "M"}}, {{"name", "N"}}}));
  const int depth = kSanitizedBuild ? 10000 : 100000;
  const int first = int(b.doc["nodes"].size());
  for (int n = 0; n < depth; ++n) {
    json node = {{"translation", {0.001, 0, 0}}};
    node["children"] = {n + 1 < depth ? first + n + 1 : 0};
    b.add_node(node);
  }
  b.write(dir / "deep.gltf", {first});
  const json report = export_json({(dir / "deep.gltf").string(), "-o", (dir / "out.glb").string(), "--ao-samples", "8"});
  ASSERT_FALSE(report.is_null());
  EXPECT_EQ(report["ao_rays"], 4 * 8);
  const gltf::Document out = read_output(dir / "out.glb");
  EXPECT_EQ(out.json["nodes"].size(), std::size_t(depth + 2));
  EXPECT_TRUE(out.json["meshes"][0]["primitives"][0]["attributes"].contains("COLOR_0"));
}

TEST(CliExport, BadInputIsRefusedAndNothingIsWritten) {
  TempDir dir;
  fs::create_directories(dir / "out");
  const std::string out = (dir / "out" / "x.glb").string();
  GltfBuilder good = quad_scene(json::array({{{"name", "M"}}, {{"name", "N"}}}));
  good.write(dir / "good.gltf", {0});
  std::ofstream(dir / "malformed.gltf") << "{\"asset\": {\"version\": \"2.0\"";
  {
    GltfBuilder b = quad_scene(json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}, json::object()}));
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["images"] = {{{"uri", "missing.png"}}};
    b.write(dir / "missing.gltf", {0});
    b.doc["images"] = {{{"uri", "../../etc/passwd"}}};
    b.write(dir / "escape.gltf", {0});
    b.doc["images"] = {{{"uri", "/etc/passwd"}}};
    b.write(dir / "absolute.gltf", {0});
    b.doc["images"] = {{{"uri", "data:image/png;base64," + base64(std::vector<unsigned char>(
                                                               {0x89, 'P', 'N', 'G', 0, 0, 0, 0}))}}};
    b.write(dir / "broken-data.gltf", {0});
    // A header of 200 rows over the pixels of 2: every image is decoded to its last row before export.
    std::string rows;
    for (int y = 0; y < 2; ++y) rows += std::string(1, '\0') + std::string(9, char(40 * y));
    const std::string short_png = kPngSignature + png_ihdr(3, 200, 8, 2) + png_chunk("IDAT", deflated(rows)) + png_chunk("IEND", "");
    b.doc["images"] = {{{"uri", "data:image/png;base64," + base64(std::vector<unsigned char>(short_png.begin(), short_png.end()))}}};
    b.write(dir / "truncated.gltf", {0});
  }
  {
    GltfBuilder b = quad_scene(json::array({json::object(), json::object()}));
    b.doc["accessors"][0]["count"] = 400;
    b.write(dir / "range.gltf", {0});
  }
  {
    // A spec-gloss factor holding a string: nlohmann's type_error ended the process (exit 134, and
    // stderr silenced at that moment).
    GltfBuilder b = quad_scene(json::array(
        {{{"extensions", {{"KHR_materials_pbrSpecularGlossiness", {{"diffuseFactor", "red"}}}}}}, json::object()}));
    b.doc["extensionsUsed"] = {"KHR_materials_pbrSpecularGlossiness"};
    b.write(dir / "factor.gltf", {0});
  }
  write_bytes(dir / "chunks.glb", std::string("glTF\x02\0\0\0\x40\0\0\0\xff\0\0\0JSON{}", 22) + std::string(42, ' '));
  using Case = std::pair<std::string, std::string>;
  for (const auto& [file, problem] :
       {Case{"malformed.gltf", "not a valid glTF"}, Case{"missing.gltf", "image 0: 'missing.png' cannot be read"},
        Case{"escape.gltf", "URI '../../etc/passwd' is outside the glTF's folder"},
        Case{"absolute.gltf", "URI '/etc/passwd' is outside the glTF's folder"},
        Case{"broken-data.gltf", "image 0: "}, Case{"truncated.gltf", "image 0: cannot read pixels"}, Case{"range.gltf", "accessor 0 reaches beyond its buffer"},
        Case{"chunks.glb", "not a valid glTF"},
        Case{"factor.gltf", "material 0 KHR_materials_pbrSpecularGlossiness.diffuseFactor must be 4 numbers"}}) {
    const RunResult r = matbake({"export", (dir / file).string(), "-o", out});
    EXPECT_EQ(r.exit_code, 1) << file << ": " << r.err;
    expect_one_error_line(r, (dir / file).string(), problem);
  }
  const std::string good_path = (dir / "good.gltf").string();
  for (const auto& [args, problem] :
       {Case{"--material", "Nope=a.png,b.png"}, Case{"--material", "no-equals-sign"}, Case{"--ao-into", "COLOR_1"}}) {
    const RunResult r = matbake({"export", good_path, "-o", out, args, problem});
    EXPECT_NE(r.exit_code, 0) << problem;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  const RunResult unknown = matbake({"export", good_path, "-o", out, "--material", "Nope=" + good_path + "," + good_path});
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_TRUE(list_folder(dir / "out").empty());
  const RunResult over = matbake({"export", good_path, "-o", good_path});
  EXPECT_EQ(over.exit_code, 2) << over.err;
}

// Emission above 1 (an EXR emissive source) is carried by KHR_materials_emissive_strength, the
// factor or texture divided by the maximum; negative emission is refused naming the file; every
// result passes the validator (a factor of 2 did not: VALUE_NOT_IN_RANGE).
TEST(CliExport, EmissionAboveOneBecomesEmissiveStrength) {
  TempDir dir;
  GltfBuilder b = quad_scene(json::array({{{"name", "glow"}}, {{"name", "other"}}}));
  b.write(dir / "in.gltf", {0});
  const auto build_with = [&](const std::vector<double>& emissive, int width) {
    write_raw(dir / "e.exr", width, 1, 3, "float", emissive);
    write_bytes(dir / "m.toml", "output = \"out\"\n[materials.glow]\nsources = { base_color = \"0.5\", metallic = 0, "
                                "roughness = 0.5, emissive = \"e.exr\" }\n[scenes.s]\ninput = \"in.gltf\"\n");
    return matbake({"build", (dir / "m.toml").string()});
  };
  for (double value : {2.0, 1e30, 0.25}) {
    SCOPED_TRACE(value);
    const RunResult r = build_with({value, value, value, value, value, value}, 2);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const gltf::Document out = read_output(dir / "out/s.glb");
    const json& material = out.json["materials"][0];
    const double strength = value > 1 ? value : 1;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(material["emissiveFactor"][c].get<double>(), value / strength, 1e-6);
    if (value > 1) {
      EXPECT_NEAR(material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>() / value, 1, 1e-6);
    } else {
      EXPECT_FALSE(material.contains("extensions"));
    }
    expect_validator_clean(dir / "out/s.glb");
  }
  // A textured one: the texture holds emission / 4 (sRGB-encoded), the strength 4.
  const RunResult textured = build_with({4, 2, 1, 0, 0.5, 0.04}, 2);
  ASSERT_EQ(textured.exit_code, 0) << textured.err;
  const gltf::Document out = read_output(dir / "out/s.glb");
  const json& material = out.json["materials"][0];
  EXPECT_EQ(material["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>(), 4.0);
  const RawImage texels = texture_pixels(out, material["emissiveTexture"]["index"], dir / "e.png");
  const double expected[] = {1, 0.5, 0.25, 0, 0.125, 0.01};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(code_to_linear(texels.samples[std::size_t(i)]), expected[i], 0.004) << i;
  expect_validator_clean(dir / "out/s.glb");
  // Negative emission: one error line naming the file.
  const RunResult negative = build_with({-5, -5, -5, 1, 1, 1}, 2);
  EXPECT_EQ(negative.exit_code, 1);
  EXPECT_NE(negative.err.find((dir / "e.exr").string() + ": emissive values below 0 (-5.000000 at x 0, y 0)"),
            std::string::npos) << negative.err;
}

}  // namespace
}  // namespace matbake::test
