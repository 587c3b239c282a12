// Geometry for delivery (delivery/geometry.cpp): a generated scene — a wavy grid with normals,
// tangents, colours and UVs beyond [0, 1] read through a texture transform, placed by a rotated,
// scaled node and by its child — exported with KHR_mesh_quantization and EXT_meshopt_compression,
// read back by matbake's reader and compared vertex by vertex, in world space, against the scene as
// it was: every attribute within the bound docs/delivery.md states, every triangle kept, the file
// validator-clean; compression alone is lossless.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "lib/src/delivery/geometry.hpp"
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

constexpr int kSide = 24;  // grid vertices per side
const glm::dvec2 kUvLow{-1.5, 0.2}, kUvHigh{3.25, 0.9};

// The grid: z = 0.3 sin(2x) cos(3y) over [−1, 1]², its analytic normals and tangents, colours and UVs
// that vary per vertex; every position distinct, so vertices match by position alone.
void write_grid_scene(const fs::path& file) {
  test::GltfBuilder b;
  std::vector<float> positions, normals, tangents, colours, uvs;
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const double x = -1 + 2.0 * i / (kSide - 1), y = -1 + 2.0 * j / (kSide - 1);
      const double dzdx = 0.6 * std::cos(2 * x) * std::cos(3 * y), dzdy = -0.9 * std::sin(2 * x) * std::sin(3 * y);
      const glm::dvec3 n = glm::normalize(glm::dvec3(-dzdx, -dzdy, 1)), t = glm::normalize(glm::dvec3(1, 0, dzdx));
      positions.insert(positions.end(), {float(x), float(y), float(0.3 * std::sin(2 * x) * std::cos(3 * y))});
      normals.insert(normals.end(), {float(n.x), float(n.y), float(n.z)});
      tangents.insert(tangents.end(), {float(t.x), float(t.y), float(t.z), (i + j) % 2 ? 1.0f : -1.0f});
      colours.insert(colours.end(), {float(i) / (kSide - 1), float(j) / (kSide - 1), 0.5f, float((i * 7 + j * 3) % 11) / 10});
      const glm::dvec2 uv = kUvLow + (kUvHigh - kUvLow) * glm::dvec2(double(i) / (kSide - 1), double(j) / (kSide - 1));
      uvs.insert(uvs.end(), {float(uv.x), float(uv.y)});
    }
  }
  std::vector<std::uint32_t> indices;
  for (std::uint32_t j = 0; j + 1 < kSide; ++j) {
    for (std::uint32_t i = 0; i + 1 < kSide; ++i) {
      const std::uint32_t a = j * kSide + i, c = a + kSide;
      indices.insert(indices.end(), {a, a + 1, c + 1, a, c + 1, c});
    }
  }
  const int mesh = b.add_mesh(b.add_vec3(positions), b.add_indices(indices), 4, b.add_floats(normals, "VEC3", 3));
  json& attributes = b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["attributes"];
  attributes["TANGENT"] = b.add_floats(tangents, "VEC4", 4);
  attributes["COLOR_0"] = b.add_floats(colours, "VEC4", 4);
  attributes["TEXCOORD_0"] = b.add_floats(uvs, "VEC2", 2);
  b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["material"] = 0;
  b.doc["images"] = {{{"uri", "wood.png"}}};
  b.doc["textures"] = {{{"source", 0}}};
  json info = {{"index", 0}};
  info["extensions"]["KHR_texture_transform"] = {{"offset", {0.25, -0.5}}, {"rotation", 0.3}, {"scale", {2.0, 0.5}}};
  b.doc["materials"] = json::array();
  b.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", info}}}});
  b.doc["extensionsUsed"] = {"KHR_texture_transform"};
  fs::copy_file(fs::path(MATBAKE_SOURCE_DIR) / "examples/textures/wood_albedo.png", file.parent_path() / "wood.png");
  const int child = b.add_node({{"mesh", mesh}, {"translation", {0.0, 0.0, 2.0}}, {"scale", {1.5, 1.5, 1.5}}});
  const int parent = b.add_node({{"mesh", mesh}, {"rotation", {0.0, 0.3826834, 0.0, 0.9238795}}, {"scale", {2.0, 2.0, 2.0}},
                                 {"translation", {5.0, -1.0, 0.5}}, {"children", {child}}});
  b.write(file, {parent});
}

scene::Scene load(const fs::path& file) {
  auto s = scene::load_scene(file, {.texcoords = true});
  EXPECT_TRUE(s) << s.error().to_string();
  return s ? std::move(*s) : scene::Scene{};
}

gltf::UvTransform base_colour_transform(const fs::path& file) {
  const gltf::Document doc = test::read_output(file);
  auto t = gltf::uv_transform_of(doc.json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"], file.string(), "");
  EXPECT_TRUE(t) << t.error().to_string();
  return t ? *t : gltf::UvTransform{};
}

// For each vertex of `b`, the vertex of `a` nearest to it in world space.
std::vector<std::size_t> nearest_vertices(const scene::Instance& a, const scene::Instance& b) {
  std::vector<std::size_t> out;
  for (const scene::Vec3& p : b.positions) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < a.positions.size(); ++k) {
      if (glm::length(a.positions[k] - p) < glm::length(a.positions[best] - p)) best = k;
    }
    out.push_back(best);
  }
  return out;
}

// The triangles as vertex-index triples of `a`, each rotated to start at its smallest index: the
// same multiset for two scenes means no triangle was lost, added, flipped or broken.
std::multiset<std::array<std::uint32_t, 3>> triangles_in(const scene::Instance& i, const std::vector<std::size_t>& to_a) {
  std::multiset<std::array<std::uint32_t, 3>> out;
  for (auto t : i.triangles) {
    std::array<std::uint32_t, 3> v{std::uint32_t(to_a[t[0]]), std::uint32_t(to_a[t[1]]), std::uint32_t(to_a[t[2]])};
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());
    out.insert(v);
  }
  return out;
}

struct Errors {
  double position = 0, normal = 0, uv = 0, colour = 0;  // normal: |Δn| of the unit world normals
};

// The largest differences between the scenes' matching vertices, UVs through each file's transform.
Errors compare(const fs::path& original, const fs::path& delivered) {
  scene::Scene a = load(original), b = load(delivered);
  // Instances in the order of their centres along x (the delivered file places meshes by new nodes).
  for (scene::Scene* s : {&a, &b}) {
    const auto centre_x = [](const scene::Instance& i) {
      double x = 0;
      for (const scene::Vec3& p : i.positions) x += p.x;
      return x / double(std::max<std::size_t>(i.positions.size(), 1));
    };
    std::sort(s->instances.begin(), s->instances.end(), [&](auto& l, auto& r) { return centre_x(l) < centre_x(r); });
  }
  const gltf::UvTransform ta = base_colour_transform(original), tb = base_colour_transform(delivered);
  Errors e;
  EXPECT_EQ(a.instances.size(), b.instances.size());
  for (std::size_t k = 0; k < std::min(a.instances.size(), b.instances.size()); ++k) {
    const scene::Instance &ia = a.instances[k], &ib = b.instances[k];
    EXPECT_EQ(ia.positions.size(), ib.positions.size());
    const std::vector<std::size_t> to_a = nearest_vertices(ia, ib);
    std::vector<std::size_t> identity(ia.positions.size());
    for (std::size_t v = 0; v < identity.size(); ++v) identity[v] = v;
    EXPECT_EQ(triangles_in(ib, to_a), triangles_in(ia, identity)) << "instance " << k;
    for (std::size_t v = 0; v < ib.positions.size(); ++v) {
      const std::size_t w = to_a[v];
      e.position = std::max(e.position, double(glm::length(ib.positions[v] - ia.positions[w])));
      e.normal = std::max(e.normal, double(glm::length(ib.normals[v] - ia.normals[w])));
      e.uv = std::max(e.uv, glm::length(tb.apply(glm::dvec2(ib.texcoords[0][v])) - ta.apply(glm::dvec2(ia.texcoords[0][w]))));
      for (int c = 0; c < 4; ++c) e.colour = std::max(e.colour, double(std::abs(ib.colors[v][c] - ia.colors[w][c])));
    }
  }
  return e;
}

void export_ok(const fs::path& in, const fs::path& out, const std::vector<std::string>& flags) {
  std::vector<std::string> args = {"export", in.string(), "-o", out.string()};
  args.insert(args.end(), flags.begin(), flags.end());
  const test::RunResult r = test::matbake(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

TEST(DeliveryGeometry, QuantizedAndCompressedReadsBackWithinTheStatedBoundsWithEveryTriangleKept) {
  test::TempDir dir;
  const fs::path scene = dir / "grid.gltf";
  write_grid_scene(scene);
  for (int bits : {10, 14}) {
    const fs::path out = dir / ("grid_q" + std::to_string(bits) + ".gltf");
    export_ok(scene, out, {"--mesh-quantization", "--position-bits", std::to_string(bits), "--texcoord-bits", std::to_string(bits),
                           "--mesh-compression", "meshopt"});
    const Errors e = compare(scene, out);
    // World scale: 2 (the parent), 3 (the child under it); the grid's longest side: 2.
    const double position_bound = std::sqrt(3.0) * delivery::position_error_bound(2.0, bits) * 3.0;
    const glm::dvec2 range = kUvHigh - kUvLow;
    // The transform scales u by 2 and v by 0.5 (a rotation keeps lengths).
    const double uv_bound = std::hypot(2 * delivery::texcoord_error_bound(range.x, bits), 0.5 * delivery::texcoord_error_bound(range.y, bits));
    EXPECT_LE(e.position, position_bound * (1 + 1e-3)) << bits;
    EXPECT_GT(e.position, position_bound / 20) << bits << ": quantized at all";
    EXPECT_LE(e.uv, uv_bound * (1 + 1e-3) + 1e-6) << bits;
    EXPECT_LE(e.colour, delivery::kColourError + 1e-6) << bits;
    // Components off by 0.5/127 move a unit vector by at most √3 · 0.5/127 (renormalising: about as much).
    EXPECT_LE(e.normal, std::sqrt(3.0) * delivery::kNormalComponentError * 1.01) << bits;

    const gltf::Document doc = test::read_output(out);
    for (const char* required : {"KHR_mesh_quantization", "EXT_meshopt_compression", "KHR_texture_transform"}) {
      EXPECT_NE(std::find(doc.json["extensionsRequired"].begin(), doc.json["extensionsRequired"].end(), required),
                doc.json["extensionsRequired"].end())
          << required;
    }
    const json& attributes = doc.json["meshes"][0]["primitives"][0]["attributes"];
    EXPECT_EQ(doc.json["accessors"][attributes["POSITION"].get<std::size_t>()]["componentType"], gltf::kUnsignedShort);
    EXPECT_EQ(doc.json["accessors"][attributes["NORMAL"].get<std::size_t>()]["componentType"], gltf::kByte);
    EXPECT_EQ(doc.json["accessors"][attributes["TEXCOORD_0"].get<std::size_t>()]["componentType"], gltf::kUnsignedShort);
    EXPECT_FALSE(attributes.contains("TANGENT")) << "no normal map reads it";
    MATBAKE_VALIDATE_OR_SKIP(report, out);
    EXPECT_EQ(report->errors, 0) << report->summary;
    EXPECT_EQ(report->warnings, 0) << report->summary;
  }
}

// The grid scene rearranged for joining: its mesh copied into meshes placed by a rotated, scaled node
// and its mirrored child (each with positions of its own), two instances of one mesh, a node an
// animation moves, and a node whose mesh shares its positions with those two.
void write_join_scene(const fs::path& file) {
  write_grid_scene(file);
  json scene = json::parse(test::read_bytes(file));
  const json mesh = scene["meshes"][0];
  scene["meshes"] = {mesh, mesh, mesh, mesh, mesh};
  for (int own : {0, 1}) {
    scene["accessors"].push_back(scene["accessors"][mesh["primitives"][0]["attributes"]["POSITION"].get<std::size_t>()]);
    scene["meshes"][own]["primitives"][0]["attributes"]["POSITION"] = scene["accessors"].size() - 1;
  }
  scene["nodes"] = {{{"mesh", 0}, {"rotation", {0.0, 0.3826834, 0.0, 0.9238795}}, {"scale", {2.0, 2.0, 2.0}},
                     {"translation", {5.0, -1.0, 0.5}}, {"children", {1}}, {"name", "static"}},
                    {{"mesh", 1}, {"translation", {0.0, 0.0, 2.0}}, {"scale", {-1.5, 1.5, 1.5}}, {"name", "mirrored"}},
                    {{"mesh", 2}, {"translation", {-4.0, 0.0, 0.0}}, {"name", "instance"}},
                    {{"mesh", 2}, {"translation", {-4.0, 3.0, 0.0}}, {"name", "instance"}},
                    {{"mesh", 3}, {"translation", {0.0, -4.0, 0.0}}, {"name", "animated"}},
                    {{"mesh", 4}, {"translation", {0.0, 8.0, 0.0}}, {"name", "shared"}}};
  scene["scenes"][0]["nodes"] = {0, 2, 3, 4, 5};
  // The animation's keys: times 0 and 1, two translations, in a buffer of their own.
  const std::vector<float> keys = {0, 1, 0, -4, 0, 1, -4, 0};
  const std::string bytes(reinterpret_cast<const char*>(keys.data()), keys.size() * sizeof(float));
  test::write_bytes(file.parent_path() / "keys.bin", bytes);
  scene["buffers"].push_back({{"uri", "keys.bin"}, {"byteLength", bytes.size()}});
  const std::size_t buffer = scene["buffers"].size() - 1, views = scene["bufferViews"].size(), accessors = scene["accessors"].size();
  scene["bufferViews"].push_back({{"buffer", buffer}, {"byteOffset", 0}, {"byteLength", 8}});
  scene["bufferViews"].push_back({{"buffer", buffer}, {"byteOffset", 8}, {"byteLength", 24}});
  scene["accessors"].push_back({{"bufferView", views}, {"componentType", 5126}, {"count", 2}, {"type", "SCALAR"}, {"min", {0}}, {"max", {1}}});
  scene["accessors"].push_back({{"bufferView", views + 1}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}});
  scene["animations"] = {{{"samplers", {{{"input", accessors}, {"output", accessors + 1}}}},
                          {"channels", {{{"sampler", 0}, {"target", {{"node", 4}, {"path", "translation"}}}}}}}};
  test::write_bytes(file, scene.dump());
}

// Every instance of a scene as one, in world space (the loader flips a mirrored instance's triangles).
scene::Instance all_in_one(const scene::Scene& s) {
  scene::Instance out;
  for (const scene::Instance& i : s.instances) {
    const auto base = std::uint32_t(out.positions.size());
    out.positions.insert(out.positions.end(), i.positions.begin(), i.positions.end());
    out.normals.insert(out.normals.end(), i.normals.begin(), i.normals.end());
    for (auto t : i.triangles) out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return out;
}

// Joined, the two static meshes become one primitive in world space — the same triangles facing the
// same way (the mirrored one's winding flipped), normals within float rounding — under one new node,
// their emptied nodes gone; the instanced mesh, the animated node and the mesh sharing the instances'
// positions stay as they were (joined, each would be a copy). With
// quantization and meshopt on top: one grid, validator-clean.
TEST(DeliveryGeometry, JoinedMeshesAreTheSameTrianglesInWorldSpaceAndInstancesAndAnimationsStay) {
  test::TempDir dir;
  const fs::path scene = dir / "join.gltf";
  write_join_scene(scene);
  const fs::path out = dir / "joined.gltf";
  export_ok(scene, out, {"--join-meshes"});
  const gltf::Document doc = test::read_output(out);
  ASSERT_EQ(doc.json["meshes"].size(), 4u);  // the three kept, then the joined one
  EXPECT_EQ(doc.json["meshes"][3]["primitives"].size(), 1u);
  std::vector<std::string> names;
  for (const gltf::Json& n : doc.json["nodes"]) names.push_back(n.value("name", ""));
  EXPECT_EQ(names, (std::vector<std::string>{"instance", "instance", "animated", "shared", "joined"}));
  EXPECT_EQ(doc.json["animations"][0]["channels"][0]["target"]["node"], 2);
  EXPECT_EQ(doc.json["nodes"][0]["mesh"], doc.json["nodes"][1]["mesh"]);

  const scene::Scene before = load(scene), after = load(out);
  EXPECT_EQ(after.instances.size(), 5u);
  const scene::Instance a = all_in_one(before), b = all_in_one(after);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  const std::vector<std::size_t> to_a = nearest_vertices(a, b);
  std::vector<std::size_t> identity(a.positions.size());
  std::iota(identity.begin(), identity.end(), std::size_t(0));
  EXPECT_EQ(triangles_in(b, to_a), triangles_in(a, identity));
  double position = 0, normal = 0;
  for (std::size_t v = 0; v < b.positions.size(); ++v) {
    position = std::max(position, double(glm::length(b.positions[v] - a.positions[to_a[v]])));
    normal = std::max(normal, double(glm::length(b.normals[v] - a.normals[to_a[v]])));
  }
  EXPECT_LT(position, 1e-5);
  EXPECT_LT(normal, 1e-5);

  const fs::path packed = dir / "packed.glb";
  export_ok(scene, packed, {"--join-meshes", "--mesh-quantization", "--mesh-compression", "meshopt"});
  EXPECT_EQ(load(packed).instances.size(), 5u);
  MATBAKE_VALIDATE_OR_SKIP(report, packed);
  EXPECT_EQ(report->errors, 0) << report->summary;
  EXPECT_EQ(report->warnings, 0) << report->summary;
}

// The join scene as Draco and as gltfpack's quantized meshopt file (Debian's tools) joined: read,
// decoded or dequantized, into world space — every triangle kept, every vertex within the input's
// own quantization step of the plain scene, validator-clean.
TEST(DeliveryGeometry, DracoAndQuantizedInputJoinsInWorldSpace) {
  test::TempDir dir;
  const fs::path scene = dir / "join.gltf";
  write_join_scene(scene);
  const scene::Scene plain = load(scene);
  const double extent = glm::length(plain.bounds_max - plain.bounds_min);
  const scene::Instance a = all_in_one(plain);
  struct Input {
    const char* tool;
    std::vector<std::string> args;
    double step;
  };
  for (const Input& in : {Input{"draco_transcoder", {}, extent / 2048}, Input{"gltfpack", {"-c", "-kn"}, extent / 16384}}) {
    if (test::tool_path(in.tool).empty()) GTEST_SKIP() << in.tool << " is not installed (Debian packages draco and gltfpack; scripts/deps.sh)";
    const fs::path made = dir / (std::string(in.tool) + ".glb"), out = dir / (std::string(in.tool) + "_joined.glb");
    std::vector<std::string> args = {"-i", scene.string()};
    args.insert(args.end(), in.args.begin(), in.args.end());
    args.insert(args.end(), {"-o", made.string()});
    const test::RunResult r = test::run(test::tool_path(in.tool), args);
    ASSERT_EQ(r.exit_code, 0) << in.tool << ": " << r.err;
    const test::RunResult e = test::matbake({"--json", "export", made.string(), "-o", out.string(), "--join-meshes"});
    ASSERT_EQ(e.exit_code, 0) << e.err;
    EXPECT_NE(e.out.find("joined (join_meshes)"), std::string::npos) << in.tool << ": " << e.out;  // gltfpack re-makes the meshes: 3 join
    const scene::Instance b = all_in_one(load(out));
    EXPECT_EQ(b.triangles.size(), a.triangles.size()) << in.tool;
    double farthest = 0;
    for (const scene::Vec3& p : b.positions) {
      double nearest = INFINITY;
      for (const scene::Vec3& q : a.positions) nearest = std::min(nearest, double(glm::length(p - q)));
      farthest = std::max(farthest, nearest);
    }
    EXPECT_LE(farthest, in.step) << in.tool;
    MATBAKE_VALIDATE_OR_SKIP(report, out);
    EXPECT_EQ(report->errors, 0) << report->summary;
    EXPECT_EQ(report->warnings, 0) << report->summary;
  }
}

TEST(DeliveryGeometry, CompressionAloneIsLosslessAndSmaller) {
  test::TempDir dir;
  const fs::path scene = dir / "grid.gltf", out = dir / "grid_meshopt.gltf", plain = dir / "grid_plain.gltf";
  write_grid_scene(scene);
  export_ok(scene, out, {"--mesh-compression", "meshopt"});
  export_ok(scene, plain, {});
  const Errors e = compare(scene, out);
  EXPECT_EQ(e.position, 0);
  EXPECT_EQ(e.uv, 0);
  EXPECT_EQ(e.colour, 0);
  EXPECT_EQ(e.normal, 0);
  EXPECT_LT(double(fs::file_size(dir / "grid_meshopt.bin")), double(fs::file_size(dir / "grid_plain.bin")) * 0.8);
  MATBAKE_VALIDATE_OR_SKIP(report, out);
  EXPECT_EQ(report->errors, 0) << report->summary;
  EXPECT_EQ(report->warnings, 0) << report->summary;
}

// A mesh with a primitive the pass cannot rewrite (lines) keeps its positions as floats, since its
// node's dequantization would also scale the lines; the other mesh is quantized; both read back.
TEST(DeliveryGeometry, AMeshWithAPrimitiveKeptAsReadKeepsFloatPositions) {
  test::TempDir dir;
  test::GltfBuilder b;
  const int square = b.add_vec3({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
  const int mixed = b.add_mesh(square, b.add_indices({0, 1, 2, 0, 2, 3}));
  b.doc["meshes"][std::size_t(mixed)]["primitives"].push_back({{"attributes", {{"POSITION", square}}}, {"mode", 1}});
  const int plain = b.add_mesh(b.add_vec3({0, 0, 1, 2, 0, 1, 2, 2, 1}));
  const fs::path in = dir / "mixed.gltf", out = dir / "mixed_q.glb";
  b.write(in, {b.add_node({{"mesh", mixed}}), b.add_node({{"mesh", plain}, {"translation", {3.0, 0.0, 0.0}}})});
  export_ok(in, out, {"--mesh-quantization"});
  const gltf::Document doc = test::read_output(out);
  const auto position_type = [&](std::size_t m, std::size_t p) {
    return doc.json["accessors"][doc.json["meshes"][m]["primitives"][p]["attributes"]["POSITION"].get<std::size_t>()]["componentType"].get<int>();
  };
  EXPECT_EQ(position_type(0, 0), gltf::kFloat);
  EXPECT_EQ(position_type(0, 1), gltf::kFloat);
  EXPECT_EQ(position_type(1, 0), gltf::kUnsignedShort);
  const scene::Scene before = load(in), after = load(out);
  ASSERT_EQ(after.instances.size(), 2u);  // lines are not ray-cast: one triangle list per mesh
  for (std::size_t i = 0; i < 2; ++i) {
    for (std::size_t v = 0; v < before.instances[i].positions.size(); ++v) {
      const auto& p = before.instances[i].positions[v];
      const auto& q = after.instances[i].positions;
      const double nearest = glm::length(*std::min_element(q.begin(), q.end(), [&](auto& l, auto& r) { return glm::length(l - p) < glm::length(r - p); }) - p);
      EXPECT_LE(nearest, std::sqrt(3.0) * delivery::position_error_bound(2.0, 14)) << i << " " << v;
    }
  }
  MATBAKE_VALIDATE_OR_SKIP(report, out);
  EXPECT_EQ(report->errors, 0) << report->summary;
}

// A position no grid holds is the input's fault: one error line naming the file and the primitive,
// and nothing written.
TEST(DeliveryGeometry, ANonFinitePositionIsAnErrorAtItsPrimitive) {
  test::TempDir dir;
  test::GltfBuilder b;
  const int mesh = b.add_mesh(b.add_floats({0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0}, "VEC3", 3));
  const fs::path in = dir / "infinite.gltf", out = dir / "infinite_q.glb";
  b.write(in, {b.add_node({{"mesh", mesh}})});
  const test::RunResult r = test::matbake({"export", in.string(), "-o", out.string(), "--mesh-quantization"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err, "matbake: error: " + in.string() + ": /meshes/0/primitives/0: POSITION element 2 is not finite\n");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace matbake
