// MikkTSpace tangents (bake/mikktspace.hpp): closed forms (a plane, its mirror, a cylinder's
// circumference, a vertex's angle-weighted mean), the reference's rules for triangles without UV
// area or without area, and agreement with three.js's port of the reference on hard meshes (seams,
// mirrored UVs, poles, flipped and zero-area UVs, an edge of three triangles).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "lib/src/bake/mikktspace.hpp"
#include "support/runtime.hpp"
#include "support/temp_dir.hpp"

namespace matbake::bake {
namespace {

// Triangles given corner by corner.
struct Mesh {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> texcoords;
  void corner(glm::vec3 p, glm::vec3 n, glm::vec2 uv) {
    positions.push_back(p);
    normals.push_back(n);
    texcoords.push_back(uv);
  }
  std::vector<glm::vec4> tangents() const { return mikktspace_tangents({positions, normals, texcoords}); }
};

void expect_near(glm::vec4 got, glm::vec4 want, float tolerance, const std::string& what) {
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(got[c], want[c], tolerance) << what << " component " << c;
}

// A quad in the XY plane mapped u = x, v = y: tangent +X, bitangent +Y = cross(+Z, +X), sign +1.
// Mirrored (u = 1 - x) the tangent is -X and cross(+Z, -X) = -Y is the opposite of the bitangent +Y:
// sign -1.
TEST(MikkTSpace, APlaneMappedAlongXHasTangentXAndItsMirrorTheOpposite) {
  for (const bool mirrored : {false, true}) {
    Mesh m;
    const glm::vec3 z(0, 0, 1);
    for (const glm::vec2 p : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 0), glm::vec2(1, 1), glm::vec2(0, 1)}) {
      m.corner({p, 0}, z, {mirrored ? 1 - p.x : p.x, p.y});
    }
    for (const glm::vec4 t : m.tangents()) expect_near(t, mirrored ? glm::vec4(-1, 0, 0, -1) : glm::vec4(1, 0, 0, 1), 1e-6f, "");
  }
}

// A cylinder of n flat sides mapped u around, v up: every face's u direction is its chord, whose part
// along a vertex's normal the projection removes, so each vertex's tangent is the circumference's
// direction (-sin θ, cos θ, 0) whatever the angle weights, with sign +1 (cross(N, T) = +Z = up).
TEST(MikkTSpace, ACylindersTangentIsItsCircumference) {
  const int n = 7;
  Mesh m;
  const auto at = [&](int j, float z) {
    const double a = 2 * std::numbers::pi * j / n;
    return std::pair{glm::vec3(float(std::cos(a)), float(std::sin(a)), z), glm::vec2(float(j) / n, z)};
  };
  for (int j = 0; j < n; ++j) {
    for (const auto& [jj, z] : {std::pair{j, 0.0f}, {j + 1, 0.0f}, {j + 1, 1.0f}, {j, 0.0f}, {j + 1, 1.0f}, {j, 1.0f}}) {
      const auto [p, uv] = at(jj, z);
      m.corner(p, glm::vec3(p.x, p.y, 0), uv);
    }
  }
  const std::vector<glm::vec4> t = m.tangents();
  for (std::size_t c = 0; c < t.size(); ++c) {
    const glm::vec3 p = m.positions[c];
    expect_near(t[c], glm::vec4(-p.y, p.x, 0, 1), 2e-6f, "corner " + std::to_string(c));
  }
}

// One vertex O between two triangles of one orientation: A (corner angle π/2 at O, u along +X) and
// B (π/4, u along (1, -1)/√2): O's tangent is their angle-weighted mean. D, sharing A's edge with UVs
// of no area, joins A's groups and adds nothing; its third corner, in no group, keeps (1, 0, 0, -1).
// E, of two equal positions, copies its vertices' tangents from the first good triangle.
TEST(MikkTSpace, AVertexWeightsItsTrianglesByAngleAndTheReferencesRulesHold) {
  Mesh m;
  const glm::vec3 z(0, 0, 1), o(0, 0, 0), x(1, 0, 0), y(0, 1, 0);
  m.corner(o, z, {0, 0}), m.corner(x, z, {1, 0}), m.corner(y, z, {0, 1});                       // A
  m.corner(o, z, {0, 0}), m.corner(y, z, {0, 1}), m.corner({-1, 1, 0}, z, {-1, 0});              // B
  m.corner(x, z, {1, 0}), m.corner(o, z, {0, 0}), m.corner({0, -1, 0}, z, {0.5f, 0});            // D
  m.corner(y, z, {0, 1}), m.corner(y, z, {0, 1}), m.corner(x, z, {1, 0});                        // E
  const std::vector<glm::vec4> t = m.tangents();
  const glm::vec3 mean = glm::normalize(float(std::numbers::pi / 2) * x + float(std::numbers::pi / 4) * glm::normalize(glm::vec3(1, -1, 0)));
  expect_near(t[0], {mean, 1}, 1e-6f, "A at O");
  expect_near(t[3], {mean, 1}, 1e-6f, "B at O");
  expect_near(t[7], {mean, 1}, 1e-6f, "D at O");
  expect_near(t[6], t[1], 0, "D at x: A's");
  expect_near(t[8], {1, 0, 0, -1}, 0, "D's own corner");
  expect_near(t[9], t[2], 0, "E at y: A's");
  expect_near(t[11], t[1], 0, "E at x: A's");
}

// ---- Against three.js's port of the reference --------------------------------------------------

// A UV sphere: a seam (u = 0 and 1 at one meridian) and poles whose triangles have two corners at
// the pole (degenerate), `rings` × `segments`.
void add_uv_sphere(Mesh& m, int rings, int segments) {
  const auto vertex = [&](int i, int j) {
    const double theta = std::numbers::pi * i / rings, phi = 2 * std::numbers::pi * j / segments;
    const glm::vec3 p(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
    m.corner(p + glm::vec3(3, 0, 0), p, {float(j) / float(segments), float(i) / float(rings)});
  };
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1);
      vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1);
    }
  }
}

// A wavy grid whose right half mirrors the left's u (a mirror seam sharing its vertices), with some
// triangles' UVs flipped, some of no UV area, and one edge shared by three triangles.
void add_hard_grid(Mesh& m, std::mt19937& random) {
  const int n = 8;
  std::uniform_real_distribution<float> jitter(-0.2f, 0.2f);
  std::vector<glm::vec3> p((n + 1) * (n + 1));
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) p[std::size_t(i * (n + 1) + j)] = {float(j) + jitter(random), float(i) + jitter(random), 0.3f * std::sin(float(i + j))};
  }
  const auto uv = [&](int i, int j) { return glm::vec2(float(j <= n / 2 ? j : n - j) / n, float(i) / n); };
  const auto normal = [&](int i, int j) { return glm::normalize(glm::vec3(0.2f * std::cos(float(i)), 0.1f * float(j - n / 2), 1)); };
  int triangle = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const std::pair<int, int> quad[2][3] = {{{i, j}, {i, j + 1}, {i + 1, j + 1}}, {{i, j}, {i + 1, j + 1}, {i + 1, j}}};
      for (const auto& tri : quad) {
        ++triangle;
        for (const auto& [a, b] : tri) {
          glm::vec2 t = uv(a, b);
          if (triangle % 11 == 0) t.x = 1 - t.x;  // flipped
          if (triangle % 13 == 0) t = {0.25f, 0.25f};  // no UV area
          m.corner(p[std::size_t(a * (n + 1) + b)], normal(a, b), t);
        }
      }
    }
  }
  // A third triangle on the grid's first edge.
  m.corner(p[0], normal(0, 0), uv(0, 0)), m.corner(p[1], normal(0, 1), uv(0, 1)), m.corner({0.5f, 0, 1}, {0, -1, 0}, {0.1f, 0.5f});
}

TEST(MikkTSpace, AgreesWithThreeJsPortOfTheReferenceOnHardMeshes) {
  Mesh m;
  add_uv_sphere(m, 9, 12);
  std::mt19937 random(7);
  add_hard_grid(m, random);
  std::vector<float> positions, normals, texcoords;
  for (std::size_t c = 0; c < m.positions.size(); ++c) {
    positions.insert(positions.end(), {m.positions[c].x, m.positions[c].y, m.positions[c].z});
    normals.insert(normals.end(), {m.normals[c].x, m.normals[c].y, m.normals[c].z});
    texcoords.insert(texcoords.end(), {m.texcoords[c].x, m.texcoords[c].y});
  }
  test::TempDir dir;
  std::string why_not;
  const auto oracle = test::mikktspace_in_three(dir.path(), positions, normals, texcoords, why_not);
  if (!oracle) GTEST_SKIP() << why_not;
  const std::vector<glm::vec4> ours = m.tangents();
  ASSERT_EQ(oracle->size(), 4 * ours.size());
  int signs_apart = 0;
  for (std::size_t c = 0; c < ours.size(); ++c) {
    const glm::vec4 theirs((*oracle)[4 * c], (*oracle)[4 * c + 1], (*oracle)[4 * c + 2], (*oracle)[4 * c + 3]);
    expect_near(ours[c], theirs, 1e-4f, "corner " + std::to_string(c));
    signs_apart += ours[c].w != theirs.w;
  }
  EXPECT_EQ(signs_apart, 0);
}

}  // namespace
}  // namespace matbake::bake
