// Scene loading: transforms, instancing, strips and fans, mirroring, what is skipped, bad files;
// vertex normals with the three weightings of ch. 12.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <fstream>
#include <numbers>

#include "matbake/scene.hpp"
#include "support/build_kind.hpp"
#include "support/gltf_files.hpp"
#include "support/temp_dir.hpp"

namespace matbake::scene {
namespace {

using test::GltfBuilder;
using test::kSanitizedBuild;
using test::TempDir;

void expect_vec(const Vec3& a, const Vec3& b, float tolerance = 1e-6f) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

TEST(SceneLoad, TransformsInstancesAndOnlyTheSceneNodes) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = b.add_mesh(b.add_vec3(kTriangle), b.add_indices({0, 1, 2}));
  const int child = b.add_node({{"mesh", mesh}, {"translation", {0, 0, 1}}});
  const int parent = b.add_node({{"children", {child}}, {"scale", {2, 2, 2}}});
  const int second = b.add_node({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1}}});
  b.add_node({{"mesh", mesh}, {"translation", {9, 9, 9}}});  // not in the scene
  b.write(dir / "s.gltf", {parent, second});
  auto s = load_scene(dir / "s.gltf");
  ASSERT_TRUE(s) << s.error().to_string();
  ASSERT_EQ(s->instances.size(), 2u);
  expect_vec(s->instances[0].positions[1], {2, 0, 2});  // scale 2 applied after the child's translation
  expect_vec(s->instances[1].positions[2], {5, 1, 0});
  EXPECT_EQ(s->instances[0].triangles.size(), 1u);
  expect_vec(s->bounds_min, {0, 0, 0});
  expect_vec(s->bounds_max, {6, 2, 2});
}

TEST(SceneLoad, StripsFansMirroringAndSkippedModes) {
  TempDir dir;
  GltfBuilder b;
  const std::vector<float> quad = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const int strip = b.add_mesh(b.add_vec3(quad), -1, 5);
  const int fan = b.add_mesh(b.add_vec3(quad), b.add_indices({0, 1, 3, 2}), 6);
  const int lines = b.add_mesh(b.add_vec3(quad), -1, 1);
  const int n0 = b.add_node({{"mesh", strip}});
  const int n1 = b.add_node({{"mesh", fan}, {"scale", {-1, 1, 1}}});
  const int n2 = b.add_node({{"mesh", lines}});
  b.write(dir / "m.gltf", {n0, n1, n2});
  auto s = load_scene(dir / "m.gltf");
  ASSERT_TRUE(s) << s.error().to_string();
  ASSERT_EQ(s->instances.size(), 2u);
  // Strip {0,1,2}, {1,3,2} (odd triangles swap to keep the winding), both facing +z.
  EXPECT_EQ(s->instances[0].triangles, (std::vector<std::array<std::uint32_t, 3>>{{0, 1, 2}, {1, 3, 2}}));
  // Fan {1,3,0}, {3,2,0}, then swapped by the mirroring scale: still facing +z in the world.
  EXPECT_EQ(s->instances[1].triangles, (std::vector<std::array<std::uint32_t, 3>>{{1, 0, 3}, {3, 0, 2}}));
  for (const Instance& inst : s->instances) {
    for (const auto& t : inst.triangles) {
      const Vec3 n = glm::cross(inst.positions[t[1]] - inst.positions[t[0]], inst.positions[t[2]] - inst.positions[t[0]]);
      EXPECT_GT(n.z, 0) << "mesh " << inst.mesh;
    }
  }
  ASSERT_EQ(s->notes.size(), 1u);
  EXPECT_EQ(s->notes[0], "1 point or line primitives ignored");
}

TEST(SceneLoad, NormalsFollowTheInverseTranspose) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = b.add_mesh(b.add_vec3(kTriangle), -1, 4, b.add_vec3({1, 1, 0, 1, 1, 0, 1, 1, 0}));
  b.write(dir / "n.gltf", {b.add_node({{"mesh", mesh}, {"scale", {2, 1, 1}}})});
  auto s = load_scene(dir / "n.gltf");
  ASSERT_TRUE(s);
  // A plane x + y = c scaled by 2 in x has the normal (1/2, 1, 0), normalized.
  expect_vec(s->instances[0].normals[0], glm::normalize(Vec3(0.5f, 1, 0)));
}

void expect_refused(const std::filesystem::path& file, const std::string& problem) {
  auto s = load_scene(file);
  ASSERT_FALSE(s) << file;
  EXPECT_EQ(s.error().path, file.string());
  EXPECT_NE(s.error().message.find(problem), std::string::npos) << s.error().message;
}

TEST(SceneLoad, BadFilesAreRefusedWithTheReason) {
  TempDir dir;
  std::ofstream(dir / "broken.gltf") << "{ not json";
  expect_refused(dir / "broken.gltf", "not a valid glTF");
  expect_refused(dir / "none.gltf", "no such file");
  {
    GltfBuilder b;
    const int positions = b.add_vec3(kTriangle);
    b.doc["accessors"][positions]["count"] = 1000;
    b.write(dir / "range.gltf", {b.add_node({{"mesh", b.add_mesh(positions)}})});
    expect_refused(dir / "range.gltf", "accessor 0 reaches beyond its buffer");
  }
  {
    GltfBuilder b;
    b.write(dir / "index.gltf", {b.add_node({{"mesh", b.add_mesh(b.add_vec3(kTriangle), b.add_indices({0, 1, 7}))}})});
    expect_refused(dir / "index.gltf", "index 7 at 2 is beyond the 3 vertices");
  }
  for (const auto& [name, uri, problem] :
       {std::tuple{"escape.gltf", "../../etc/passwd", "is outside the glTF's folder"},
        std::tuple{"absolute.gltf", "/etc/passwd", "is outside the glTF's folder"}}) {
    GltfBuilder b;
    b.write(dir / name, {b.add_node({{"mesh", b.add_mesh(b.add_vec3(kTriangle))}})});
    nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / name));
    doc["buffers"][0]["uri"] = uri;
    std::ofstream(dir / name) << doc.dump();
    expect_refused(dir / name, problem);
  }
  {
    GltfBuilder b;
    b.write(dir / "lines.gltf", {b.add_node({{"mesh", b.add_mesh(b.add_vec3(kTriangle), -1, 1)}})});
    expect_refused(dir / "lines.gltf", "no triangles in the default scene");
  }
  {
    GltfBuilder b;
    b.write(dir / "nan.gltf", {b.add_node({{"mesh", b.add_mesh(b.add_vec3({0, 0, 0, 1, 0, 0, 0, NAN, 0}))}})});
    expect_refused(dir / "nan.gltf", "mesh 0 primitive 0: POSITION of vertex 2 is not finite");
  }
  {
    // A GLB whose JSON chunk claims more bytes than the file has.
    std::string glb = std::string("glTF") + std::string("\x02\0\0\0", 4) + std::string("\x40\0\0\0", 4) +
                      std::string("\xff\0\0\0", 4) + "JSON{}";
    glb.resize(64, ' ');
    std::ofstream(dir / "chunks.glb", std::ios::binary) << glb;
    expect_refused(dir / "chunks.glb", "not a valid glTF");
  }
  {
    // Draco data that is not Draco: the decoder's refusal, at the extension's pointer.
    GltfBuilder b;
    const int positions = b.add_vec3(kTriangle);
    const int mesh = b.add_mesh(positions);
    b.doc["meshes"][0]["primitives"][0]["extensions"] = {
        {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
    b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    b.write(dir / "draco.gltf", {b.add_node({{"mesh", mesh}})});
    expect_refused(dir / "draco.gltf", "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression: Draco's decoder refused it");
  }
  {
    GltfBuilder b;
    const int a = b.add_node({{"children", {1}}});
    b.add_node({{"children", {0}}});
    b.write(dir / "cycle.gltf", {a});
    expect_refused(dir / "cycle.gltf", "is its own ancestor");
  }
  {
    // Node 2 under two parents: the spec's strict trees; refusing it also keeps a hostile file
    // from multiplying instances (a chain of shared children doubles them at each level).
    GltfBuilder b;
    const int shared = 2;
    const int a = b.add_node({{"children", {shared}}});
    const int c = b.add_node({{"children", {shared}}});
    b.add_node({{"mesh", b.add_mesh(b.add_vec3(kTriangle))}});
    b.write(dir / "parents.gltf", {a, c});
    expect_refused(dir / "parents.gltf", "node 2 is its own ancestor or has two parents");
  }
}

TEST(SceneLoad, DeepNodeChainIsWalkedWithoutRecursion) {
  // 200 000 nested nodes, each translating by 1 along x: the triangle at the bottom sits at x = 200 000
  // (a recursive walk overflows the stack long before). The sanitizer build walks 20 000: its memory
  // checks need no more, and the full chain costs it four minutes of CI.
  TempDir dir;
  GltfBuilder b;
  const int depth = kSanitizedBuild ? 20000 : 200000;
  const int mesh = b.add_mesh(b.add_vec3(kTriangle));
  for (int n = 0; n < depth; ++n) {
    nlohmann::json node = {{"translation", {1, 0, 0}}};
    if (n + 1 < depth) node["children"] = {n + 1};
    else node["mesh"] = mesh;
    b.add_node(node);
  }
  b.write(dir / "deep.gltf", {0});
  auto s = load_scene(dir / "deep.gltf");
  ASSERT_TRUE(s) << s.error().to_string();
  ASSERT_EQ(s->instances.size(), 1u);
  expect_vec(s->instances[0].positions[1], {float(depth) + 1, 0, 0});
}

TEST(VertexNormals, ThreeWeightings) {
  // A vertex at the origin shared by a large face in the xy-plane (normal +z, area 2, angle 90°)
  // and a small one in the xz-plane (normal +y, area 0.5, angle 45°).
  const std::vector<Vec3> p = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5f, 0, 0.5f}};
  const std::vector<std::array<std::uint32_t, 3>> t = {{0, 1, 2}, {0, 3, 1}};
  const Vec3 small_normal = glm::normalize(glm::cross(p[3] - p[0], p[1] - p[0]));  // (0, 1, 0)
  expect_vec(vertex_normals(p, t, NormalWeighting::equal).normals[0], glm::normalize(Vec3(0, 0, 1) + small_normal));
  expect_vec(vertex_normals(p, t, NormalWeighting::area).normals[0],
             glm::normalize(2.0f * Vec3(0, 0, 1) + 0.5f * small_normal));
  const float quarter = std::numbers::pi_v<float> / 4;
  expect_vec(vertex_normals(p, t, NormalWeighting::angle).normals[0],
             glm::normalize(2 * quarter * Vec3(0, 0, 1) + quarter * small_normal));
}

TEST(VertexNormals, DegenerateFacesAndLonelyVertices) {
  const std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {5, 5, 5}};
  // One good face, one zero-area face (collinear), vertex 4 in no face.
  const std::vector<std::array<std::uint32_t, 3>> t = {{0, 1, 2}, {0, 1, 3}};
  const NormalResult r = vertex_normals(p, t, NormalWeighting::area, {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 0, 0}});
  EXPECT_EQ(r.degenerate_faces, 1u);
  EXPECT_EQ(r.fallbacks, 2u);
  expect_vec(r.normals[0], {0, 0, 1});
  expect_vec(r.normals[3], {1, 0, 0});  // its normal from the file
  expect_vec(r.normals[4], {0, 0, 1});  // the primitive's area-weighted normal
  // Scale-free: the same shapes at 1e-4 and 1e4 units.
  for (float scale : {1e-4f, 1e4f}) {
    std::vector<Vec3> q;
    for (const Vec3& v : p) q.push_back(v * scale);
    const NormalResult s = vertex_normals(q, t, NormalWeighting::area);
    EXPECT_EQ(s.degenerate_faces, 1u) << scale;
    expect_vec(s.normals[0], {0, 0, 1});
  }
}

}  // namespace
}  // namespace matbake::scene
