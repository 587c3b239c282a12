// Writing glTF again: buffers merged, images copied or embedded, inputs never overwritten, and the
// baked values read back exactly from COLOR_0 and _AO, per placement of an instanced mesh.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "lib/src/gltf/document.hpp"
#include "lib/src/gltf/json_text.hpp"
#include "lib/src/gltf/prune.hpp"
#include "lib/src/gltf/vertex_occlusion.hpp"
#include "matbake/ao.hpp"
#include "matbake/scene.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/temp_dir.hpp"

namespace matbake {
namespace {

namespace fs = std::filesystem;
using test::float_accessor;
using test::GltfBuilder;
using test::TempDir;

const std::vector<float> kFloor = {0, 0, 0, -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
const std::vector<std::uint32_t> kFan = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1};


// A floor whose buffer is an external .bin and which names an image in a subfolder by an
// escaped URI.
fs::path write_external_scene(const fs::path& folder) {
  GltfBuilder b;
  b.add_node({{"mesh", b.add_mesh(b.add_vec3(kFloor), b.add_indices(kFan))}});
  b.doc["images"] = {{{"uri", "tex/a%20b.png"}}};
  b.write(folder / "scene.gltf", {0});
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(folder / "scene.gltf"));
  doc["buffers"][0]["uri"] = "geometry.bin";
  std::ofstream(folder / "scene.gltf") << doc.dump();
  test::write_bytes(folder / "geometry.bin", std::string(b.bytes.begin(), b.bytes.end()));
  fs::create_directories(folder / "tex");
  test::write_raw(folder / "tex" / "a b.png", 1, 1, 3, "uint8", {10, 20, 30});
  return folder / "scene.gltf";
}

// The written text is nlohmann's but for floating-point numbers: those that are float32 values in
// their shortest float32 form, the others in their shortest double form, whole ones without ".0";
// each reads back as the value written (a float32 one as that float32).
TEST(GltfJsonText, NumbersAreShortAndReadBackAsThemselves) {
  const gltf::Json no_floats = gltf::Json::parse(R"({"asset":{"version":"2.0","generator":"x\u0001\"y"},"nodes":[{"children":[1,2]},{},{"name":"é"}],"e":[],"o":{},"b":[true,false,null],"n":-7})");
  EXPECT_EQ(gltf::json_text(no_floats), no_floats.dump());
  EXPECT_EQ(gltf::json_text(no_floats, 2), no_floats.dump(2));
  const double step = 1.0 / 16383;  // not a float32: its double's shortest form
  const gltf::Json numbers = {{"f", {0.0, 1.0, -0.5, 16383.0, double(float(step)), double(0.1f), 1e30, double(1e-30f)}},
                              {"d", {step, 0.1, 1e300}},
                              {"nan", std::nan("")}};
  EXPECT_EQ(gltf::json_text(numbers),
            R"({"f":[0,1,-0.5,16383,6.103888e-05,0.1,1e+30,1e-30],"d":[6.103888176768602e-05,0.1,1e+300],"nan":null})");
  const gltf::Json back = gltf::Json::parse(gltf::json_text(numbers, 2));
  for (std::size_t i = 0; i < numbers["f"].size(); ++i) {
    EXPECT_EQ(float(back["f"][i].get<double>()), float(numbers["f"][i].get<double>())) << i;
  }
  for (std::size_t i = 0; i < numbers["d"].size(); ++i) EXPECT_EQ(back["d"][i].get<double>(), numbers["d"][i].get<double>()) << i;
  EXPECT_TRUE(back["nan"].is_null());
}

TEST(GltfDocument, GltfToAnotherFolderMergesBuffersAndCopiesImages) {
  TempDir dir;
  fs::create_directories(dir / "in");
  fs::create_directories(dir / "out");
  const fs::path input = write_external_scene(dir / "in");
  auto doc = gltf::read_document(input);
  ASSERT_TRUE(doc) << doc.error().to_string();
  ASSERT_EQ(doc->buffers.size(), 1u);
  EXPECT_EQ(doc->buffers[0].size(), test::read_bytes(dir / "in" / "geometry.bin").size());

  const int extra = gltf::add_float_accessor(*doc, {0.25f, 0.5f}, 2, "SCALAR");  // a second buffer
  {
    auto written = gltf::write_document(*doc, dir / "out" / "copy.gltf");
    ASSERT_TRUE(written) << written.error().to_string();
  }
  EXPECT_EQ(test::list_folder(dir / "out"), (std::vector<std::string>{"copy.bin", "copy.gltf", "tex"}));
  EXPECT_EQ(test::read_bytes(dir / "out" / "tex" / "a b.png"), test::read_bytes(dir / "in" / "tex" / "a b.png"));

  auto back = gltf::read_document(dir / "out" / "copy.gltf");
  ASSERT_TRUE(back) << back.error().to_string();
  ASSERT_EQ(back->json["buffers"].size(), 1u);
  EXPECT_EQ(back->json["buffers"][0]["uri"], "copy.bin");
  EXPECT_EQ(float_accessor(*back, extra), (std::vector<float>{0.25f, 0.5f}));
  for (const auto& view : back->json["bufferViews"]) EXPECT_EQ(view["byteOffset"].get<std::size_t>() % 4, 0u);
  auto a = scene::load_scene(input), c = scene::load_scene(dir / "out" / "copy.gltf");
  ASSERT_TRUE(a && c);
  EXPECT_EQ(a->instances[0].positions, c->instances[0].positions);
  EXPECT_EQ(a->instances[0].triangles, c->instances[0].triangles);
}

TEST(GltfDocument, GlbHoldsEveryBufferAndImageInOneChunk) {
  TempDir dir;
  const fs::path input = write_external_scene(dir.path());
  auto doc = gltf::read_document(input);
  ASSERT_TRUE(doc);
  ASSERT_TRUE(gltf::write_document(*doc, dir / "one.glb"));
  const std::string bytes = test::read_bytes(dir / "one.glb");
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  ASSERT_GE(bytes.size(), 28u);
  EXPECT_EQ(bytes.substr(0, 4), "glTF");
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), bytes.size());
  const std::uint32_t json_length = u32(12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(bytes.substr(16, 4), "JSON");
  EXPECT_EQ(bytes.substr(20 + json_length + 4, 4), std::string("BIN\0", 4));
  EXPECT_EQ(20 + json_length + 8 + u32(20 + json_length), bytes.size());

  auto back = gltf::read_document(dir / "one.glb");
  ASSERT_TRUE(back) << back.error().to_string();
  const gltf::Json& image = back->json["images"][0];
  EXPECT_FALSE(image.contains("uri"));
  EXPECT_EQ(image["mimeType"], "image/png");
  const gltf::Json& view = back->json["bufferViews"][image["bufferView"].get<std::size_t>()];
  const std::string png = test::read_bytes(dir / "tex" / "a b.png");
  ASSERT_EQ(view["byteLength"].get<std::size_t>(), png.size());
  EXPECT_EQ(std::memcmp(back->buffers[0].data() + view["byteOffset"].get<std::size_t>(), png.data(), png.size()), 0);
  auto s = scene::load_scene(dir / "one.glb");
  ASSERT_TRUE(s) << s.error().to_string();
  EXPECT_EQ(s->instances[0].triangles.size(), 4u);
}

TEST(GltfDocument, NeverWritesOverItsInputs) {
  TempDir dir;
  const fs::path input = write_external_scene(dir.path());
  auto doc = gltf::read_document(input);
  ASSERT_TRUE(doc);
  const auto before = test::list_folder(dir.path());
  const std::string original = test::read_bytes(dir / "geometry.bin");
  for (const fs::path& out : {input, dir / "geometry.gltf", dir / "out.txt", dir / "geometry.bin" / "x.glb"}) {
    const auto s = gltf::write_document(*doc, out);
    ASSERT_FALSE(s) << out;
    // The error names the file that is an input: the .gltf's own buffer beside it for geometry.gltf.
    EXPECT_EQ(s.error().path, (out == dir / "geometry.gltf" ? dir / "geometry.bin" : out).string());
  }
  EXPECT_EQ(test::list_folder(dir.path()), before);
  EXPECT_EQ(test::read_bytes(dir / "geometry.bin"), original);
}

TEST(GltfDocument, PercentDecoding) {
  EXPECT_EQ(gltf::decode_uri("tex/a%20b%2Fc.png"), "tex/a b/c.png");
  EXPECT_EQ(gltf::decode_uri("100%"), "100%");
  EXPECT_EQ(gltf::decode_uri("%zz"), "%zz");
}

// What the scene reaches through extensions stays, renumbered: a material named only by
// KHR_materials_variants, and the per-instance accessor of EXT_mesh_gpu_instancing.
TEST(GltfPrune, ExtensionReferencesSurviveAndFollowTheirObjects) {
  TempDir dir;
  GltfBuilder b;
  const int unused_positions = b.add_vec3({0, 0, 0, 1, 0, 0, 0, 1, 0});  // accessor 0: read by nothing
  const int mesh = b.add_mesh(b.add_vec3(kFloor), b.add_indices(kFan));
  const int offsets = b.add_vec3({0, 0, 0, 5, 0, 0});
  b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["material"] = 0;
  b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["extensions"] = {
      {"KHR_materials_variants", {{"mappings", {{{"material", 2}, {"variants", {0}}}}}}}};
  b.doc["materials"] = {{{"name", "Base"}}, {{"name", "Unused"}}, {{"name", "Variant"}}};
  b.doc["extensionsUsed"] = {"KHR_materials_variants", "EXT_mesh_gpu_instancing"};
  b.doc["extensions"] = {{"KHR_materials_variants", {{"variants", {{{"name", "red"}}}}}}};
  b.add_node({{"mesh", mesh}, {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", offsets}}}}}}}});
  b.write(dir / "in.gltf", {0});
  auto doc = gltf::read_document(dir / "in.gltf");
  ASSERT_TRUE(doc) << doc.error().to_string();
  const std::vector<std::string> removed = gltf::prune_unreachable(*doc);
  EXPECT_EQ(removed, (std::vector<std::string>{"material 1 'Unused'", "accessor " + std::to_string(unused_positions),
                                               "buffer view 0"}));
  const gltf::Json& json = doc->json;
  ASSERT_EQ(json["materials"].size(), 2u);
  EXPECT_EQ(json["materials"][1]["name"], "Variant");
  EXPECT_EQ(json["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][0]["material"], 1);
  const int translation = json["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"];
  EXPECT_EQ(float_accessor(*doc, translation), (std::vector<float>{0, 0, 0, 5, 0, 0}));
  ASSERT_TRUE(gltf::write_document(*doc, dir / "out.glb"));
  auto s = scene::load_scene(dir / "out.glb");
  ASSERT_TRUE(s) << s.error().to_string();
  EXPECT_EQ(s->instances[0].positions.size(), 5u);
}

// An edit's prune (`before`: what the file reached as read) removes only what the edit left unused,
// and never what a kept object still names: material 1 (used by no mesh, so kept as it came) names
// texture 0, which the edit took from material 0; texture 1 goes, as do its image and sampler;
// texture 2 (unused as read) stays. Then everything kept names only what exists.
TEST(GltfPrune, AnEditsPruneRemovesWhatTheEditLeftUnusedAndNothingAKeptObjectNames) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = b.add_mesh(b.add_vec3(kFloor), b.add_indices(kFan));
  b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["material"] = 0;
  b.doc["materials"] = {{{"name", "Used"}, {"normalTexture", {{"index", 1}}}, {"occlusionTexture", {{"index", 0}}}},
                        {{"name", "Unused"}, {"emissiveTexture", {{"index", 0}}}}};
  b.doc["samplers"] = {{{"wrapS", 33071}}, {{"wrapT", 33071}}, {{"magFilter", 9728}}};
  b.doc["images"] = {{{"uri", "a.png"}}, {{"uri", "b.png"}}, {{"uri", "c.png"}}};
  b.doc["textures"] = {{{"source", 0}, {"sampler", 0}}, {{"source", 1}, {"sampler", 1}}, {{"source", 2}, {"sampler", 2}}};
  b.add_node({{"mesh", mesh}});
  b.write(dir / "in.gltf", {0});
  auto doc = gltf::read_document(dir / "in.gltf");
  ASSERT_TRUE(doc) << doc.error().to_string();
  const gltf::Reachable as_read = gltf::reachable(doc->json);
  EXPECT_EQ(as_read.textures, (std::vector<bool>{true, true, false}));
  EXPECT_EQ(as_read.materials, (std::vector<bool>{true, false}));
  // The edit: material 0's maps become a new texture of image 0 (appended).
  doc->json["textures"].push_back({{"source", 0}});
  doc->json["materials"][0]["normalTexture"]["index"] = 3;
  doc->json["materials"][0].erase("occlusionTexture");
  const std::vector<std::string> removed = gltf::prune_unreachable(*doc, nullptr, &as_read);
  EXPECT_EQ(removed, (std::vector<std::string>{"texture 1", "image 1", "sampler 1"}));
  const gltf::Json& json = doc->json;
  ASSERT_EQ(json["textures"].size(), 3u);
  EXPECT_EQ(json["materials"][1]["emissiveTexture"]["index"], 0);  // still texture 0: image a, sampler 0
  const auto source_and_sampler = [&](std::size_t t) { return std::pair{json["textures"][t]["source"].get<int>(), json["textures"][t]["sampler"].get<int>()}; };
  EXPECT_EQ(source_and_sampler(0), std::pair(0, 0));
  EXPECT_EQ(source_and_sampler(1), std::pair(1, 1));  // texture 2 as read: image c, sampler 2
  EXPECT_EQ(json["images"][1]["uri"], "c.png");
  EXPECT_EQ(json["samplers"][1]["magFilter"], 9728);
  EXPECT_EQ(json["materials"][0]["normalTexture"]["index"], 2);
  // Without `before`, the unused material goes, and texture 0 with it only if nothing else names it.
  const std::vector<std::string> rest = gltf::prune_unreachable(*doc);
  EXPECT_EQ(rest, (std::vector<std::string>{"material 1 'Unused'", "texture 0", "texture 1", "image 1", "sampler 0", "sampler 1"}));
}

// A quad under a roof and the same mesh placed again in the open; the floor has its own colours.
fs::path write_instanced_scene(const fs::path& folder) {
  GltfBuilder b;
  const int quad = b.add_mesh(b.add_vec3(kFloor), b.add_indices(kFan));
  const int roof = b.add_mesh(b.add_vec3({0, 0, 1, -9, 9, 1, 9, 9, 1, 9, -9, 1, -9, -9, 1}), b.add_indices(kFan));
  b.doc["meshes"][std::size_t(quad)]["primitives"][0]["attributes"]["COLOR_0"] =
      b.add_floats({1, 0.5f, 0.25f, 0.5f, 1, 1, 1, 1, 0, 0, 0, 0, 0.2f, 0.4f, 0.6f, 0.8f, 1, 1, 1, 0}, "VEC4", 4);
  b.write(folder / "instanced.gltf", {b.add_node({{"mesh", quad}}), b.add_node({{"mesh", roof}}),
                                      b.add_node({{"mesh", quad}, {"translation", {100, 0, 0}}})});
  return folder / "instanced.gltf";
}

// The instanced scene loaded and baked (binary AO, 64 rays, d_max 1000).
struct Baked {
  fs::path input;
  scene::Scene scene;
  ao::Bake bake;
};
Baked bake_instanced_scene(const fs::path& folder) {
  Baked b;
  b.input = write_instanced_scene(folder);
  auto s = scene::load_scene(b.input);
  EXPECT_TRUE(s) << s.error().to_string();
  b.scene = std::move(*s);
  ao::Options o;
  o.samples = 64;
  o.falloff = ao::Falloff::none;
  o.absolute_distance = 1e3;
  auto baked = ao::bake(b.scene, o);
  EXPECT_TRUE(baked);
  b.bake = std::move(*baked);
  return b;
}

// The scene file written again with the baked values, as `bake-ao -o` does.
bool write_with_values(const fs::path& input, const scene::Scene& scene, const ao::Bake& bake, ao::Into into,
                       const fs::path& output) {
  auto doc = gltf::read_document(input);
  if (!doc) return false;
  std::vector<gltf::PlacedValues> placed;
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const scene::Instance& inst = scene.instances[k];
    placed.push_back({inst.node, inst.primitive, bake.values[k], inst.colors, inst.colors_have_alpha});
  }
  gltf::add_vertex_occlusion(*doc, placed, into);
  return bool(gltf::write_document(*doc, output));
}

TEST(AoGltfOutput, EachPlacementKeepsItsOwnValuesAndColoursAreMultiplied) {
  TempDir dir;
  const Baked b = bake_instanced_scene(dir.path());
  ASSERT_EQ(b.scene.instances.size(), 3u);
  EXPECT_LT(b.bake.values[0][0], 0.1f);  // under the roof
  EXPECT_EQ(b.bake.values[2][0], 1.0f);  // in the open

  ASSERT_TRUE(write_with_values(b.input, b.scene, b.bake, ao::Into::color_multiply, dir / "multiply.glb"));
  auto doc = gltf::read_document(dir / "multiply.glb");
  ASSERT_TRUE(doc);
  ASSERT_EQ(doc->json["meshes"].size(), 3u);             // the quad, the roof, the quad's copy
  EXPECT_EQ(doc->json["nodes"][0]["mesh"], 0);
  EXPECT_EQ(doc->json["nodes"][2]["mesh"], 2);
  auto out = scene::load_scene(dir / "multiply.glb");
  ASSERT_TRUE(out) << out.error().to_string();
  ASSERT_EQ(out->instances.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const scene::Instance& before = b.scene.instances[k];
    const scene::Instance& after = out->instances[k];
    EXPECT_EQ(after.node, before.node);
    EXPECT_EQ(after.positions, before.positions);
    ASSERT_EQ(after.colors.size(), before.positions.size()) << k;
    for (std::size_t v = 0; v < after.colors.size(); ++v) {
      const float w = b.bake.values[k][v];
      const glm::vec4 expected = before.colors.empty() ? glm::vec4(w, w, w, 1)
                                                       : glm::vec4(glm::vec3(before.colors[v]) * w, before.colors[v].a);
      EXPECT_EQ(after.colors[v], expected) << "instance " << k << " vertex " << v;
    }
    EXPECT_EQ(after.colors_have_alpha, !before.colors.empty());
  }
}

TEST(AoGltfOutput, ReplacedColoursAndTheAoAttributeHoldTheValuesExactly) {
  TempDir dir;
  const Baked b = bake_instanced_scene(dir.path());
  ASSERT_TRUE(write_with_values(b.input, b.scene, b.bake, ao::Into::color, dir / "replace.gltf"));
  auto replaced = scene::load_scene(dir / "replace.gltf");
  ASSERT_TRUE(replaced);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_FALSE(replaced->instances[k].colors_have_alpha);
    for (std::size_t v = 0; v < b.bake.values[k].size(); ++v) {
      const float w = b.bake.values[k][v];
      EXPECT_EQ(replaced->instances[k].colors[v], glm::vec4(w, w, w, 1));
    }
  }

  ASSERT_TRUE(write_with_values(b.input, b.scene, b.bake, ao::Into::attribute, dir / "attribute.gltf"));
  auto doc = gltf::read_document(dir / "attribute.gltf");
  ASSERT_TRUE(doc);
  for (std::size_t k = 0; k < 3; ++k) {
    const int mesh = doc->json["nodes"][std::size_t(b.scene.instances[k].node)]["mesh"];
    const gltf::Json& attributes = doc->json["meshes"][std::size_t(mesh)]["primitives"][0]["attributes"];
    EXPECT_EQ(float_accessor(*doc, attributes["_AO"].get<int>()), b.bake.values[k]);
    EXPECT_EQ(attributes.contains("COLOR_0"), k != 1);  // the file's own colours stay where they were
  }
}

TEST(AoGltfOutput, SameBytesEveryTime) {
  TempDir dir;
  const Baked b = bake_instanced_scene(dir.path());
  for (const char* name : {"a.glb", "b.glb", "a.gltf"}) {
    ASSERT_TRUE(write_with_values(b.input, b.scene, b.bake, ao::Into::color, dir / name));
  }
  EXPECT_EQ(test::read_bytes(dir / "a.glb"), test::read_bytes(dir / "b.glb"));
  EXPECT_EQ(test::list_folder(dir.path()),
            (std::vector<std::string>{"a.bin", "a.glb", "a.gltf", "b.glb", "instanced.gltf"}));
}

}  // namespace
}  // namespace matbake

namespace matbake {
namespace {

// Integers of a glTF given as floats beyond every integer type (found by fuzzing: nlohmann converts
// them with undefined behaviour, which UBSan reports): each is an error naming the file, and
// integer_in keeps in-range integers and refuses floats, negatives and out-of-range values.
TEST(GltfDocument, HugeFloatIntegersAreErrorsNotUndefinedBehaviour) {
  TempDir dir;
  // 12 bytes of buffer (one float VEC3), as a data: URI.
  const std::string buffer = "data:application/octet-stream;base64,AAAAAAAAAAAAAAAA";
  const char* cases[][2] = {
      {R"("byteOffset": 2.3e45)", R"("bufferView": 0)"},
      {R"("byteOffset": 0)", R"("bufferView": 1e300)"},
      {R"("count": 1e30)", R"("bufferView": 0)"},
      {R"("byteOffset": -4)", R"("bufferView": 0)"},
  };
  for (const auto& c : cases) {
    const std::string accessor_fields = std::string(c[0]) + ", " + c[1];
    const bool count_given = std::string(c[0]).find("count") != std::string::npos;
    const std::string json = R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 12, "uri": ")" + buffer +
                             R"("}], "bufferViews": [{"buffer": 0, "byteLength": 12}], "accessors": [{)" + accessor_fields +
                             (count_given ? "" : R"(, "count": 1)") + R"(, "componentType": 5126, "type": "VEC3"}]})";
    std::ofstream(dir / "bad.gltf") << json;
    auto doc = gltf::read_document(dir / "bad.gltf");
    ASSERT_FALSE(doc) << json;
    EXPECT_NE(doc.error().path.find("bad.gltf"), std::string::npos) << doc.error().to_string();
  }
  const gltf::Json values = gltf::Json::parse(R"({"a": 7, "b": 2.5, "c": -3, "d": 5000000000, "e": 1e45})");
  EXPECT_EQ(gltf::integer_in<int>(values, "a", -1, 99), 7);
  EXPECT_EQ(gltf::integer_in<int>(values, "missing", -1, 99), -1);
  EXPECT_EQ(gltf::integer_in<int>(values, "b", -1, 99), 99);
  EXPECT_EQ(gltf::integer_in<int>(values, "c", -1, 99), -3);
  EXPECT_EQ(gltf::integer_in<int>(values, "d", -1, 99), 99);
  EXPECT_EQ(gltf::integer_in<int>(values, "e", -1, 99), 99);
  EXPECT_EQ(gltf::size_in(values, "c", 0), SIZE_MAX);
  EXPECT_EQ(gltf::size_in(values, "d", 0), std::size_t{5000000000});
  EXPECT_EQ(gltf::size_in(values, "e", 0), SIZE_MAX);
  const gltf::Json made = {{"n", int(12)}, {"m", std::int64_t(-1)}};  // signed storage, as code sets it
  EXPECT_EQ(gltf::size_in(made, "n", 0), 12u);
  EXPECT_EQ(gltf::size_in(made, "m", 0), SIZE_MAX);
}

}  // namespace
}  // namespace matbake
