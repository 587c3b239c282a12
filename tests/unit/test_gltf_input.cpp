// Real-world glTF in: sparse accessors applied, every reference checked with its JSON pointer,
// KHR_texture_transform sampled exactly, Draco and meshopt files (made here by Debian's
// draco_transcoder and gltfpack) read like their plain twins and written back validator-clean.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include "lib/src/gltf/document.hpp"
#include "lib/src/gltf/texture_transform.hpp"
#include "matbake/scene.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::GltfBuilder;
using test::TempDir;

const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

TEST(GltfInput, SparseAccessorsAreApplied) {
  TempDir dir;
  GltfBuilder b;
  const int positions = b.add_vec3(kTriangle);
  const int targets = b.add_indices({2});
  const int values = b.add_vec3({5, 6, 0});
  const auto view_of = [&](int accessor) { return b.doc["accessors"][std::size_t(accessor)]["bufferView"]; };
  b.doc["accessors"][std::size_t(positions)]["sparse"] = {
      {"count", 1}, {"indices", {{"bufferView", view_of(targets)}, {"componentType", 5125}}}, {"values", {{"bufferView", view_of(values)}}}};
  b.doc["accessors"][std::size_t(positions)]["max"] = {5, 6, 0};
  // A second accessor with no view at all: zeros, then its substitutions.
  json zeros = b.doc["accessors"][std::size_t(positions)];
  zeros.erase("bufferView");
  zeros["min"] = {0, 0, 0};
  b.doc["accessors"].push_back(zeros);
  const int mesh = b.add_mesh(positions);
  const int zero_mesh = b.add_mesh(int(b.doc["accessors"].size()) - 1);
  b.write(dir / "sparse.gltf", {b.add_node({{"mesh", mesh}}), b.add_node({{"mesh", zero_mesh}})});
  auto s = scene::load_scene(dir / "sparse.gltf");
  ASSERT_TRUE(s) << s.error().to_string();
  ASSERT_EQ(s->instances.size(), 2u);
  EXPECT_EQ(s->instances[0].positions, (std::vector<scene::Vec3>{{0, 0, 0}, {1, 0, 0}, {5, 6, 0}}));
  EXPECT_EQ(s->instances[1].positions, (std::vector<scene::Vec3>{{0, 0, 0}, {0, 0, 0}, {5, 6, 0}}));
  // bake-ao writes it back with the sparse accessor as it came, and says so.
  const test::RunResult r = test::matbake({"bake-ao", (dir / "sparse.gltf").string(), "-o", (dir / "out.gltf").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["geometry"], json::array({"2 sparse accessors: applied to read, passed through as written"}));
  MATBAKE_VALIDATE_OR_SKIP(report, dir / "out.gltf");
  EXPECT_EQ(report->errors, 0) << report->summary;
}

// A valid file with one of each object kind, to break one reference at a time.
json every_kind(const fs::path& folder) {
  GltfBuilder b;
  const int positions = b.add_vec3(kTriangle);
  const int mesh = b.add_mesh(positions, b.add_indices({0, 1, 2}));
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  b.add_node({{"mesh", mesh}});
  b.write(folder / "kinds.gltf", {0});
  json doc = json::parse(std::ifstream(folder / "kinds.gltf"));
  doc["materials"] = {{{"occlusionTexture", {{"index", 0}}}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  doc["samplers"] = {json::object()};
  doc["images"] = {{{"bufferView", 0}, {"mimeType", "image/png"}}};
  doc["skins"] = {{{"joints", {0}}, {"inverseBindMatrices", 0}}};
  const json channel = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}};
  const json sampler = {{"input", 0}, {"output", 0}};
  doc["animations"] = json::array({{{"samplers", json::array({sampler})}, {"channels", json::array({channel})}}});
  return doc;
}

TEST(GltfInput, EveryOutOfRangeReferenceIsOneErrorWithItsJsonPointer) {
  TempDir dir;
  const json valid = every_kind(dir.path());
  const std::vector<std::pair<json::json_pointer, std::string>> cases = {
      {json::json_pointer("/scene"), "scene 99"},
      {json::json_pointer("/scenes/0/nodes/0"), "node 99"},
      {json::json_pointer("/nodes/0/mesh"), "mesh 99"},
      {json::json_pointer("/meshes/0/primitives/0/attributes/POSITION"), "accessor 99"},
      {json::json_pointer("/meshes/0/primitives/0/indices"), "accessor 99"},
      {json::json_pointer("/meshes/0/primitives/0/material"), "material 99"},
      {json::json_pointer("/materials/0/occlusionTexture/index"), "texture 99"},
      {json::json_pointer("/materials/0/pbrMetallicRoughness/baseColorTexture/index"), "texture 99"},
      {json::json_pointer("/textures/0/source"), "image 99"},
      {json::json_pointer("/textures/0/sampler"), "sampler 99"},
      {json::json_pointer("/images/0/bufferView"), "buffer view 99"},
      {json::json_pointer("/accessors/0/bufferView"), "buffer view 99"},
      {json::json_pointer("/bufferViews/0/buffer"), "buffer 99"},
      {json::json_pointer("/skins/0/joints/0"), "node 99"},
      {json::json_pointer("/skins/0/inverseBindMatrices"), "accessor 99"},
      {json::json_pointer("/animations/0/samplers/0/output"), "accessor 99"},
      {json::json_pointer("/animations/0/channels/0/sampler"), "animation sampler 99"},
      {json::json_pointer("/animations/0/channels/0/target/node"), "node 99"},
  };
  for (const auto& [pointer, kind] : cases) {
    json doc = valid;
    doc[pointer] = 99;
    std::ofstream(dir / "bad.gltf") << doc.dump();
    auto read = gltf::read_document(dir / "bad.gltf");
    ASSERT_FALSE(read) << pointer;
    const std::map<std::string, std::string> array_of = {
        {"scene", "scenes"},   {"node", "nodes"},     {"mesh", "meshes"},           {"accessor", "accessors"},
        {"material", "materials"}, {"texture", "textures"}, {"image", "images"},  {"sampler", "samplers"},
        {"buffer view", "bufferViews"}, {"buffer", "buffers"}};
    const std::string name = kind.substr(0, kind.size() - 3);  // "accessor 99" → "accessor"
    const std::size_t count = name == "animation sampler" ? 1 : valid[array_of.at(name)].size();
    EXPECT_EQ(read.error().message, pointer.to_string() + ": " + kind + " does not exist (the file has " + std::to_string(count) + ")")
        << pointer;
    // Through the command line: one line, exit 1, nothing written.
    const test::RunResult r = test::matbake({"export", (dir / "bad.gltf").string(), "-o", (dir / "out.glb").string()});
    EXPECT_EQ(r.exit_code, 1) << pointer;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(pointer.to_string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.glb"));
  }
  json doc = valid;
  doc["nodes"][0]["mesh"] = -1;
  std::ofstream(dir / "bad.gltf") << doc.dump();
  auto read = gltf::read_document(dir / "bad.gltf");
  ASSERT_FALSE(read);
  EXPECT_EQ(read.error().message, "/nodes/0/mesh: -1 is not a whole number from 0");  // types.hpp, before the references
}

// every_kind with the other core properties matbake passes through: a material's factors, modes
// and texture infos, a node's transform, a sampler's filters, a camera.
json every_property(const fs::path& folder) {
  json doc = every_kind(folder);
  doc["materials"][0].update({{"alphaMode", "MASK"}, {"alphaCutoff", 0.5}, {"doubleSided", true}, {"emissiveFactor", {0, 0.5, 0}},
                              {"normalTexture", {{"index", 0}, {"scale", 1}, {"texCoord", 0}}}, {"name", "m"}});
  doc["materials"][0]["pbrMetallicRoughness"].update({{"baseColorFactor", {1, 0.5, 1, 1}}, {"metallicFactor", 0}});
  doc["nodes"][0].update({{"translation", {1, 2, 3}}, {"rotation", {0, 0, 0, 1}}, {"scale", {1, 1, 1}}, {"camera", 0}});
  doc["samplers"][0] = {{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 33648}, {"wrapT", 10497}};
  doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  doc["extensionsUsed"] = json::array();
  return doc;
}

// Every place of `j` below the root, as JSON pointers, with where each holds.
void places_in(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  if (!at.empty()) out.push_back(at);
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) places_in(value, at / key, out);
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) places_in(j[i], at / i, out);
  }
}

// Each core property has one JSON type; another there was copied into outputs the validator rejects
// (TYPE_MISMATCH) or threw from a reader (a material's pbrMetallicRoughness a number).
TEST(GltfInput, EveryCorePropertyOfAnotherTypeIsOneErrorWithItsJsonPointer) {
  TempDir dir;
  const json valid = every_property(dir.path());
  std::ofstream(dir / "valid.gltf") << valid.dump();
  auto read = gltf::read_document(dir / "valid.gltf");
  ASSERT_TRUE(read) << read.error().to_string();
  std::vector<json::json_pointer> places;
  places_in(valid, json::json_pointer(), places);
  const json others[] = {nullptr, true, 2, "x", json::array(), json::object()};
  std::size_t refused = 0;
  for (const json::json_pointer& place : places) {
    const json& was = valid[place];
    for (const json& other : others) {
      if (other.type() == was.type() || (other.is_number() && was.is_number())) continue;
      json doc = valid;
      doc[place] = other;
      std::ofstream(dir / "bad.gltf", std::ios::trunc) << doc.dump();
      read = gltf::read_document(dir / "bad.gltf");
      ASSERT_FALSE(read) << place.to_string() << " = " << other.dump();
      EXPECT_EQ(read.error().message.rfind(place.to_string() + ": ", 0), 0u) << read.error().message;
      ++refused;
    }
  }
  EXPECT_GT(refused, 5 * 60u);
  // Values of the right type that glTF does not allow: each refused, and the validator agrees.
  const std::vector<std::pair<std::string, json>> cases = {
      {"/materials/0/alphaMode", "SHINY"},     {"/samplers/0/wrapS", 5},        {"/nodes/0/translation", {1, 2}},
      {"/accessors/0/count", 1.5},             {"/accessors/0/componentType", 5124}, {"/cameras/0/type", "fisheye"},
      {"/materials/0/emissiveFactor", {0, 0, 0, 0}}};
  for (const auto& [pointer, value] : cases) {
    json doc = valid;
    doc[json::json_pointer(pointer)] = value;
    std::ofstream(dir / "bad.gltf", std::ios::trunc) << doc.dump();
    read = gltf::read_document(dir / "bad.gltf");
    ASSERT_FALSE(read) << pointer;
    EXPECT_EQ(read.error().message.rfind(pointer + ": ", 0), 0u) << read.error().message;
  }
  EXPECT_EQ(read.error().message, "/materials/0/emissiveFactor: an array of 4 where glTF has 3");
  for (const auto& [pointer, value] : cases) {
    json doc = valid;
    doc[json::json_pointer(pointer)] = value;
    std::ofstream(dir / "bad.gltf", std::ios::trunc) << doc.dump();
    MATBAKE_VALIDATE_OR_SKIP(report, dir / "bad.gltf");
    EXPECT_GT(report->errors, 0) << pointer << ": " << report->summary;
  }
}

TEST(GltfInput, ControlCharactersInMessagesAreEscaped) {
  EXPECT_EQ((Error{"a\nb.gltf", "material 'x\ry\x01' \t\x7f"}.to_string()), "a\\nb.gltf: material 'x\\ry\\x01' \\t\\x7f");
  TempDir dir;
  const fs::path file = dir / "two\nlines.gltf";
  std::ofstream(file) << "{ not json";
  const test::RunResult r = test::matbake({"bake-ao", file.string(), "-o", (dir / "out.glb").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "matbake: error: " + (dir / "two\\nlines.gltf").string() + ": not a valid glTF: the JSON is malformed\n");
}

// A source whose texel (x, y) holds x + 10 y in each channel: bilinear sampling at any point
// inside it gives its coordinates back exactly, a float64 reference in closed form.
image::Image ramp(int width, int height) {
  image::Image im;
  im.width = width, im.height = height, im.channels = 1;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) im.pixels.push_back(float(x + 10 * y));
  }
  return im;
}

TEST(GltfInput, TextureTransformsSampleLikeTheExtensionsMatrix) {
  const image::Image source = ramp(8, 8);
  struct Case {
    gltf::UvTransform t;
    const char* what;
  };
  gltf::UvTransform offset, scale, rotation, all;
  offset.offset = {0.25, 0.125};
  scale.scale = {0.5, 0.25};
  rotation.rotation = 0.3;
  all.offset = {0.1, 0.2}, all.scale = {0.6, 0.7}, all.rotation = -0.4;
  for (const Case& c : {Case{offset, "offset"}, Case{scale, "scale"}, Case{rotation, "rotation"}, Case{all, "all three"}}) {
    const image::Image out = gltf::sample_through(source, c.t, Wrap::clamp_to_edge, Wrap::clamp_to_edge, 16, 16);
    for (int y = 0; y < 16; ++y) {
      for (int x = 0; x < 16; ++x) {
        // The spec's matrix, T · R · S, written out: R's columns are (cos, sin) and (−sin, cos).
        const double u = (x + 0.5) / 16 * c.t.scale.x, v = (y + 0.5) / 16 * c.t.scale.y;
        const double cu = std::cos(c.t.rotation) * u - std::sin(c.t.rotation) * v + c.t.offset.x;
        const double cv = std::sin(c.t.rotation) * u + std::cos(c.t.rotation) * v + c.t.offset.y;
        const double tx = std::clamp(cu * 8 - 0.5, 0.0, 7.0), ty = std::clamp(cv * 8 - 0.5, 0.0, 7.0);
        EXPECT_NEAR(out.pixels[std::size_t(y * 16 + x)], tx + 10 * ty, 2e-5) << c.what << " at " << x << "," << y;
      }
    }
  }
  // Repeat and mirrored repeat past the edge: one texel beyond the right edge is texel 0 or texel 7.
  gltf::UvTransform shift;
  shift.offset = {1.0, 0.0};
  const image::Image repeated = gltf::sample_through(source, shift, Wrap::repeat, Wrap::repeat, 8, 8);
  const image::Image mirrored = gltf::sample_through(source, shift, Wrap::mirrored_repeat, Wrap::repeat, 8, 8);
  EXPECT_FLOAT_EQ(repeated.pixels[0], 0.0f);
  EXPECT_FLOAT_EQ(mirrored.pixels[0], 7.0f);
}

TEST(GltfInput, MalformedTransformIsAnErrorAtItsPointer) {
  const json info = {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {1}}}}}}};
  auto t = gltf::uv_transform_of(info, "f.gltf", "/materials/0/occlusionTexture");
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().message, "/materials/0/occlusionTexture/extensions/KHR_texture_transform/offset: not two numbers");
}

}  // namespace
}  // namespace matbake

namespace matbake {
namespace {

// The example scene in compressed variants made by the tools users make them with (Debian's
// draco_transcoder and gltfpack); empty, with `why_not` said, when a tool is missing.
struct Variant {
  std::string name;
  std::string tool;
  std::vector<std::string> args;  // between input and output
  bool lossless;                  // not quantized: bakes like the plain scene (a quantized one moves
                                  // vertices that touch another surface to either side of it)
  double position_step;           // the largest distance quantization may move a vertex, in scene units
};

double mean_ao(const std::vector<std::string>& args) {
  const test::RunResult r = test::matbake(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return r.exit_code == 0 ? nlohmann::json::parse(r.out)["mean_ao"].get<double>() : -1.0;
}

// The largest distance from a vertex of `a` to the nearest vertex of `b`, over every instance.
double farthest_vertex(const scene::Scene& a, const scene::Scene& b) {
  double worst = 0;
  for (const scene::Instance& i : a.instances) {
    for (const scene::Vec3& p : i.positions) {
      double nearest = INFINITY;
      for (const scene::Instance& j : b.instances) {
        for (const scene::Vec3& q : j.positions) nearest = std::min(nearest, double(glm::length(p - q)));
      }
      worst = std::max(worst, nearest);
    }
  }
  return worst;
}

TEST(GltfInput, DracoAndMeshoptVariantsBakeAndExportLikeThePlainScene) {
  for (const char* tool : {"draco_transcoder", "gltfpack"}) {
    if (test::tool_path(tool).empty()) GTEST_SKIP() << tool << " is not installed (Debian packages draco and gltfpack; scripts/deps.sh)";
  }
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(fs::path(MATBAKE_SOURCE_DIR) / "examples" / f, dir / f);
  const fs::path plain = dir / "showroom.gltf";
  auto plain_scene = scene::load_scene(plain);
  ASSERT_TRUE(plain_scene) << plain_scene.error().to_string();
  const double extent = glm::length(plain_scene->bounds_max - plain_scene->bounds_min);
  const std::vector<Variant> variants = {
      {"draco_lossless.glb", "draco_transcoder", {"-qp", "0", "-qn", "0", "-qt", "0"}, true, 1e-6 * extent},
      {"draco.glb", "draco_transcoder", {}, false, extent / 2048},  // 11-bit positions
      {"meshopt.glb", "gltfpack", {"-c", "-noq"}, true, 1e-6 * extent},
      {"meshopt_cc.gltf", "gltfpack", {"-cc", "-noq"}, true, 1e-6 * extent},
      {"meshopt_quantized.glb", "gltfpack", {"-c"}, false, extent / 16384},  // 14-bit positions, KHR_mesh_quantization
      {"meshopt_cc_quantized.glb", "gltfpack", {"-cc"}, false, extent / 16384},
  };
  const std::vector<std::string> bake = {"--samples", "512", "--seed", "3", "--json"};
  const auto with = [](std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  const double plain_vertices = mean_ao(with({"bake-ao", plain.string(), "-o", (dir / "plain_ao.glb").string()}, bake));
  const double plain_texels =
      mean_ao(with({"bake-ao", plain.string(), "-o", (dir / "plain_tex.glb").string(), "--texture", "64"}, bake));
  for (const Variant& v : variants) {
    const fs::path file = dir / v.name;
    std::vector<std::string> args = {"-i", plain.string()};
    args = with(args, v.args);
    args = with(args, {"-o", file.string()});
    const test::RunResult made = test::run(test::tool_path(v.tool), args);
    ASSERT_EQ(made.exit_code, 0) << v.tool << ": " << made.err;
    auto decoded = scene::load_scene(file);
    ASSERT_TRUE(decoded) << decoded.error().to_string();
    EXPECT_LE(farthest_vertex(*decoded, *plain_scene), v.position_step) << v.name;
    EXPECT_LE(farthest_vertex(*plain_scene, *decoded), v.position_step) << v.name;
    const fs::path ao = dir / ("ao_" + v.name), textured = dir / ("tex_" + v.name), exported = dir / ("export_" + v.name);
    const double vertices = mean_ao(with({"bake-ao", file.string(), "-o", ao.string()}, bake));
    // gltfpack drops the UVs of materials without textures (the example's): no texture bake there.
    const bool has_uvs = v.tool == "draco_transcoder";
    const double texels = has_uvs ? mean_ao(with({"bake-ao", file.string(), "-o", textured.string(), "--texture", "64"}, bake)) : 0;
    if (v.lossless) {
      EXPECT_NEAR(vertices, plain_vertices, 1e-3) << v.name;
      if (has_uvs) {
        EXPECT_NEAR(texels, plain_texels, 1e-3) << v.name;
      }
    }
    const test::RunResult e = test::matbake({"export", file.string(), "-o", exported.string(), "--ao-samples", "16"});
    ASSERT_EQ(e.exit_code, 0) << e.err;
    // Delivered again with joined, quantized, compressed geometry (Draco made plain, meshopt and
    // quantized input joined in world space and quantized again): within one more 14-bit step of the scene.
    const fs::path redelivered = dir / ("geometry_" + v.name);
    const test::RunResult g = test::matbake({"export", file.string(), "-o", redelivered.string(), "--join-meshes", "--mesh-quantization",
                                             "--mesh-compression", "meshopt"});
    ASSERT_EQ(g.exit_code, 0) << g.err;
    auto requantized = scene::load_scene(redelivered);
    ASSERT_TRUE(requantized) << requantized.error().to_string();
    EXPECT_LE(farthest_vertex(*requantized, *plain_scene), v.position_step + extent / 16383) << v.name;
    EXPECT_LE(farthest_vertex(*plain_scene, *requantized), v.position_step + extent / 16383) << v.name;
    for (const fs::path& out : {ao, textured, exported, redelivered}) {
      if (out == textured && !has_uvs) continue;
      MATBAKE_VALIDATE_OR_SKIP(report, out);
      EXPECT_EQ(report->errors, 0) << out << ": " << report->summary;
      EXPECT_EQ(report->warnings, 0) << out << ": " << report->summary;
    }
  }
}

}  // namespace
}  // namespace matbake
