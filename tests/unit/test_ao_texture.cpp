// The texture-space AO bake against closed forms (tolerance: 3σ of the estimator at the sample count,
// or exact where the answer is), its coverage rules (each texel centre once, seams, overlaps,
// wrapping, degenerate triangles), padding against a brute-force reference, and agreement with the
// per-vertex bake.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <tuple>

#include "../../lib/src/ao/texels.hpp"
#include "matbake/ao.hpp"
#include "support/ao_scenes.hpp"
#include "support/shapes.hpp"

namespace matbake::ao {
namespace {

using scene::Instance;
using scene::Vec3;
using test::kX;
using test::kY;
using test::kZ;
using test::scene_of;
using test::square;
using test::three_sigma;


Options binary(int samples, double range) {
  Options o;
  o.samples = samples;
  o.falloff = Falloff::none;
  o.absolute_distance = range;
  return o;
}

TextureOptions size(int width, int height, int padding = 0) {
  TextureOptions t;
  t.width = width, t.height = height, t.padding = padding;
  return t;
}

TextureBake bake_one(const scene::Scene& s, const Options& o, const TextureOptions& t, TextureTarget target = {{0}}) {
  auto r = bake_textures(s, o, {target}, t);
  EXPECT_TRUE(r) << r.error().to_string();
  return r ? r->textures[0] : TextureBake{};
}

// E3(z) = ∫_0^1 e^(−z/μ) μ dμ by the midpoint rule, in float64.
double e3(double z) {
  double sum = 0;
  constexpr int kSteps = 200000;
  for (int i = 0; i < kSteps; ++i) {
    const double mu = (i + 0.5) / kSteps;
    sum += std::exp(-z / mu) * mu / kSteps;
  }
  return sum;
}

// Odd and even sizes: the fan's diagonals run through texel centres, and at odd sizes its centre
// vertex is one. Every centre is taken exactly once, nothing overlaps, an open plane is exactly 1.
TEST(TextureAo, OpenPlaneCoversEveryTexelOnceAndIsExactlyOne) {
  for (auto [w, h] : {std::pair{8, 8}, {7, 7}, {1, 1}, {7, 3}, {2, 64}, {8192, 2}, {3, 8192}}) {
    const TextureBake t = bake_one(scene_of({square({0, 0, 0}, kX, kY, 1)}), binary(64, 10), size(w, h));
    EXPECT_EQ(t.covered, std::size_t(w * h)) << w << "x" << h;
    EXPECT_EQ(t.overlapped, 0u) << w << "x" << h;
    EXPECT_EQ(t.touched, 0u);
    EXPECT_EQ(t.wrapped, 0u);
    EXPECT_EQ(t.triangles, 4u);
    ASSERT_EQ(t.values.size(), std::size_t(w * h));
    for (float v : t.values) EXPECT_EQ(v, 1.0f);
    EXPECT_EQ(t.rays, std::uint64_t(w * h) * 64);
  }
}

// Nothing outside a convex mesh occludes it: 1 at every texel centre inside a triangle, exactly,
// though the coarse icosphere's radial normals lean up to 21° from its faces: rays that leave below
// the plane of the face they start on must not meet that face (Cycles skips it too). A point on an
// edge is left out: there the face beside it can lie in front of some of those rays.
TEST(TextureAo, ConvexMeshWithSmoothNormalsIsExactlyOneInsideItsFaces) {
  const test::AtlasMesh mesh = test::icosphere_atlas(1, false);
  Instance inst;
  for (const glm::dvec3& p : mesh.positions) inst.positions.push_back(Vec3(p));
  for (const glm::dvec3& n : mesh.normals) inst.normals.push_back(Vec3(n));
  inst.triangles = mesh.triangles;
  inst.texcoords.push_back(mesh.texcoords);
  const int side = mesh.cells * 8;
  const TextureBake t = bake_one(scene_of({inst}), binary(64, 0.5), size(side, side));
  std::size_t inside = 0, below_one = 0;
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      // The centre in its cell, against the cell's triangle (corners at 0.1 and 0.9 of it).
      const double u = (i + 0.5) / side * mesh.cells, v = (j + 0.5) / side * mesh.cells;
      const double a = u - std::floor(u) - test::kAtlasCorner[0][0], b = v - std::floor(v) - test::kAtlasCorner[0][1];
      const std::size_t cell = std::size_t(std::floor(v)) * std::size_t(mesh.cells) + std::size_t(std::floor(u));
      if (cell >= mesh.triangles.size() || a < 0.01 || b < 0.01 || a + b > 0.79) continue;
      ++inside;
      below_one += t.values[std::size_t(j) * std::size_t(side) + std::size_t(i)] != 1.0f;
    }
  }
  ASSERT_GT(inside, 1000u);
  EXPECT_EQ(below_one, 0u) << "of " << inside << " texels";
}

// A UV-mapped floor (half-size 1) under a ceiling (half-size 1000, not baked, no UVs): every texel
// is 1 − 2E₃(τh) with the exponential falloff over an effectively unbounded range, and (h/D)² for
// binary AO of range D; the same at 1e-3 and 1e3 units.
TEST(TextureAo, FloorUnderACeilingMatchesClosedForms) {
  for (float unit : {1.0f, 1e-3f, 1e3f}) {
    const float h = 1 * unit;
    Instance ceiling = square({0, 0, h}, kY, kX, 1000 * unit);
    ceiling.texcoords.clear();
    const auto s = scene_of({square({0, 0, 0}, kX, kY, unit), ceiling});
    const int n = 1024;
    Options exponential;
    exponential.samples = n;
    exponential.absolute_distance = 1e4 * unit;
    exponential.tau = 1.0 * 1e4;  // τ = 1/h in units of 1/d_max
    const double expected = 1 - 2 * e3(1.0);
    const TextureBake a = bake_one(s, exponential, size(8, 8));
    for (float v : a.values) EXPECT_NEAR(v, expected, 3 * 0.5 / std::sqrt(double(n))) << unit;
    const TextureBake b = bake_one(s, binary(n, 2 * unit), size(8, 8));
    for (float v : b.values) EXPECT_NEAR(v, 0.25, three_sigma(0.25, n)) << unit;
  }
}

// A floor at the foot of a wall 2000 high and wide: each texel sees half its hemisphere; at three scales.
TEST(TextureAo, FootOfAWallIsOneHalf) {
  for (float unit : {1.0f, 1e-3f, 1e3f}) {
    const auto s = scene_of({square({0, 0, 0}, kX, kY, unit), square(Vec3(-1.001f, 0, 1000) * unit, kY, kZ, 1000 * unit)});
    const int n = 2048;
    const TextureBake t = bake_one(s, binary(n, 1e5 * unit), size(8, 8));
    for (float v : t.values) EXPECT_NEAR(v, 0.5, three_sigma(0.5, n) + 1e-3) << unit;  // the wall's top: < 1e-3
  }
}

// The floor of a closed box, wound inwards: nothing escapes, not even from the texels on its
// border, which sample the floor's edge where it meets the walls; at three scales.
TEST(TextureAo, InsideAClosedBoxIsZero) {
  for (float a : {1.0f, 1e-3f, 1e3f}) {
    const auto s = scene_of({square({0, 0, -a}, kX, kY, a), square({0, 0, a}, kY, kX, a), square({a, 0, 0}, kZ, kY, a),
                             square({-a, 0, 0}, kY, kZ, a), square({0, a, 0}, kX, kZ, a), square({0, -a, 0}, kZ, kX, a)});
    const TextureBake t = bake_one(s, binary(256, 100 * a), size(16, 16));
    for (float v : t.values) EXPECT_EQ(v, 0.0f) << a;
  }
}

// Islands that share texels: a mirrored copy, and a stacked copy under a ceiling while the first is
// open. Each texel is the mean of its surfaces; every covered texel counts as overlapped.
TEST(TextureAo, OverlappingIslandsAverageTheirSurfaces) {
  Instance open = square({0, 0, 0}, kX, kY, 1);
  Instance covered = square({10, 0, 0}, kX, kY, 1);
  for (auto& uv : covered.texcoords[0]) uv.x = 1 - uv.x;  // mirrored: the same texels, reversed
  Instance ceiling = square({10, 0, 1}, kY, kX, 1000);
  ceiling.texcoords.clear();
  ceiling.positions = {{10, 0, 1}, {9, -1, 1}, {9, 1, 1}, {11, 1, 1}, {11, -1, 1}};  // only over the copy, facing down
  const auto s = scene_of({open, covered, ceiling});
  const int n = 1024;
  const Options o = binary(n, 1e-3 + 2.0);  // the covered copy: (1/2)² at the centre of a 2×2 ceiling... bounded below
  const TextureBake both = bake_one(s, o, size(8, 8), {{0, 1}});
  const TextureBake alone = bake_one(scene_of({covered, ceiling}), o, size(8, 8));
  EXPECT_EQ(both.covered, 64u);
  EXPECT_EQ(both.overlapped, 64u);
  for (std::size_t i = 0; i < 64; ++i) EXPECT_NEAR(both.values[i], (1 + alone.values[i]) / 2, 3 * 0.5 / std::sqrt(double(n)));
}

// UVs shifted by whole periods sample the same texels with repeat; mirrored repeat flips odd periods;
// clamp-to-edge puts everything beyond [0, 1] in the edge texels. Each such triangle is counted.
TEST(TextureAo, WrappedUvsFollowTheWrapMode) {
  Instance shifted = square({0, 0, 0}, kX, kY, 1);
  for (auto& uv : shifted.texcoords[0]) uv += glm::vec2(2, -3);
  const auto s = scene_of({shifted});
  const TextureBake repeat = bake_one(s, binary(16, 10), size(8, 4));
  EXPECT_EQ(repeat.covered, 32u);
  EXPECT_EQ(repeat.overlapped, 0u);
  EXPECT_EQ(repeat.wrapped, 4u);
  TextureTarget mirrored{{0}, 0, Wrap::mirrored_repeat, Wrap::mirrored_repeat};
  EXPECT_EQ(bake_one(s, binary(16, 10), size(8, 4), mirrored).covered, 32u);  // even periods: the same
  Instance half_out = square({0, 0, 0}, kX, kY, 1);
  for (auto& uv : half_out.texcoords[0]) uv.x += 0.5f;  // u from 0.5 to 1.5
  TextureTarget clamped{{0}, 0, Wrap::clamp_to_edge, Wrap::clamp_to_edge};
  const TextureBake clamp = bake_one(scene_of({half_out}), binary(16, 10), size(8, 4), clamped);
  EXPECT_EQ(clamp.covered, 4u * 4u);  // columns 4–7, the edge column 7 taking the centres beyond
  EXPECT_EQ(clamp.overlapped, 4u);    // column 7: its own centre and four beyond
  TextureTarget repeated{{0}, 0, Wrap::repeat, Wrap::repeat};
  const TextureBake wrapped = bake_one(scene_of({half_out}), binary(16, 10), size(8, 4), repeated);
  EXPECT_EQ(wrapped.covered, 32u);
  EXPECT_EQ(wrapped.overlapped, 0u);
}

// A triangle of zero UV area is skipped and counted; one of zero area in space (but not in UV) gives
// finite values in [0, 1]; an instance without the UV set is counted, not baked.
TEST(TextureAo, DegenerateTrianglesAndMissingUvSets) {
  Instance inst = square({0, 0, 0}, kX, kY, 1);
  inst.texcoords[0][2] = inst.texcoords[0][1];  // triangle 0 has two equal UVs, triangle 1 collinear ones
  inst.positions.push_back({0.5f, 0.5f, 0});    // a zero-area space triangle with UV area: 5, 5, 0
  inst.texcoords[0].push_back({0.9f, 0.1f});
  inst.triangles.push_back({5, 0, 5});
  Instance no_uv = square({5, 0, 0}, kX, kY, 1);
  no_uv.texcoords.clear();
  Instance nan_uv = square({-5, 0, 0}, kX, kY, 1);
  nan_uv.texcoords[0][0].x = std::nanf("");  // the centre vertex: all four triangles
  nan_uv.texcoords[0][2].y = std::numeric_limits<float>::infinity();
  const TextureBake t = bake_one(scene_of({inst, no_uv, nan_uv}), binary(64, 10), size(16, 16), {{0, 1, 2}});
  EXPECT_EQ(t.degenerate_uv, 3u + 4u);  // triangles 0 and 1, the repeated-index one, and the NaN/∞ ones
  EXPECT_EQ(t.instances_without_uv, 1u);
  for (float v : t.values) EXPECT_TRUE(v >= 0 && v <= 1) << v;
  Instance flat = square({0, 0, 0}, kX, kY, 1);
  for (auto& p : flat.positions) p.y = 0;  // every triangle of zero area in space
  const TextureBake f = bake_one(scene_of({flat, square({0, 0, -1}, kX, kY, 1)}), binary(64, 10), size(8, 8));
  EXPECT_EQ(f.covered, 64u);
  for (float v : f.values) EXPECT_TRUE(v >= 0 && v <= 1) << v;
}

// A bumpy height field whose vertices sit on texel centres: the texel read at a vertex's UV is the
// per-vertex bake at that vertex, within the two estimates' combined error.
Instance height_field(int n, float spacing) {
  Instance g;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const float x = float(i) * spacing, y = float(j) * spacing;
      g.positions.push_back({x, y, 0.6f * std::sin(1.3f * x) * std::cos(0.9f * y)});
    }
  }
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const auto at = [n](int a, int b) { return std::uint32_t(b * n + a); };
      g.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      g.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  g.normals = scene::vertex_normals(g.positions, g.triangles, scene::NormalWeighting::angle).normals;
  return g;
}

// An n × n height field's grid laid over the texture: vertex (i, j) at first + (i, j) × step.
void add_grid_uvs(Instance& g, int n, glm::vec2 first, glm::vec2 step) {
  g.texcoords.emplace_back();
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) g.texcoords.back().push_back(first + step * glm::vec2(float(i), float(j)));
  }
}

TEST(TextureAo, TexelsAtVerticesAgreeWithThePerVertexBake) {
  constexpr int kN = 16;
  Instance g = height_field(kN, 0.5f);
  add_grid_uvs(g, kN, glm::vec2(0.5f / kN), glm::vec2(1.0f / kN));
  const auto s = scene_of({g});
  const int n = 1024;
  const Options o = binary(n, 3);
  const TextureBake t = bake_one(s, o, size(kN, kN));
  auto v = bake(s, o);
  ASSERT_TRUE(v);
  double worst = 0;
  for (int j = 1; j + 1 < kN; ++j) {
    for (int i = 1; i + 1 < kN; ++i) {
      const double vertex = v->values[0][std::size_t(j * kN + i)], texel = t.values[std::size_t(j * kN + i)];
      const double sigma = std::sqrt(2 * std::max(vertex * (1 - vertex), 0.01) / n);  // of the difference
      EXPECT_NEAR(texel, vertex, 4 * sigma) << i << "," << j;
      worst = std::max(worst, std::abs(texel - vertex));
    }
  }
  EXPECT_GT(worst, 0);  // two estimates, not one copied
}

// The height field cut into two UV islands along a column of vertices (duplicated, as exporters
// do), each seam 0.4 texel past a texel centre: on each side the texel beyond the island is touched
// and sampled at the seam vertex of its row, so the two sides hold the same surface point's value
// (within the estimates' error), which is the per-vertex bake's there; not the background.
TEST(TextureAo, TexelsOnBothSidesOfASeamAgree) {
  constexpr int kN = 9, kW = 32;
  const Instance g = height_field(kN, 0.5f);
  Instance split;
  split.positions = g.positions;
  split.normals = g.normals;
  split.texcoords.emplace_back();
  const int seam = 4;  // vertex column 4: x = 6.4 on the left island, 22.4 on the right one
  const auto u_of = [](int column, int island) { return (float(column) + 2.4f + 16.0f * float(island) + 0.5f) / kW; };
  for (int j = 0; j < kN; ++j) {
    for (int i = 0; i < kN; ++i) split.texcoords[0].push_back({u_of(i, i > seam), (float(j) + 0.5f) / kN});
  }
  for (int j = 0; j < kN; ++j) {  // the right island's copy of the seam column
    split.positions.push_back(g.positions[std::size_t(j * kN + seam)]);
    split.normals.push_back(g.normals[std::size_t(j * kN + seam)]);
    split.texcoords[0].push_back({u_of(seam, 1), (float(j) + 0.5f) / kN});
  }
  for (const auto& t : g.triangles) {
    const auto column = [&](int k) { return int(t[std::size_t(k)]) % kN; };
    const bool right = std::max({column(0), column(1), column(2)}) > seam;
    auto corners = t;
    for (auto& v : corners) {
      if (right && int(v) % kN == seam) v = std::uint32_t(kN * kN + int(v) / kN);
    }
    split.triangles.push_back(corners);
  }
  const auto s = scene_of({split});
  const int n = 2048;
  const Options o = binary(n, 3);
  const TextureBake t = bake_one(s, o, size(kW, kN));
  auto vertices = bake(s, o);
  ASSERT_TRUE(vertices);
  for (int j = 0; j < kN; ++j) {
    const std::size_t row = std::size_t(j * kW);
    const double left = t.values[row + 7], right = t.values[row + 22];
    const double vertex = vertices->values[0][std::size_t(j * kN + seam)];
    const double sigma = std::sqrt(2 * std::max(vertex * (1 - vertex), 0.01) / n);
    EXPECT_NEAR(left, right, 4 * sigma) << "row " << j;
    EXPECT_NEAR(left, vertex, 4 * sigma) << "row " << j;
  }
  EXPECT_EQ(t.overlapped, 0u);
  EXPECT_GE(t.touched, std::size_t(4 * kN));  // beyond both borders of both islands, in every row
  EXPECT_LT(*std::min_element(t.values.begin(), t.values.end()), 0.95f);  // the bumps occlude
}

TEST(TextureAo, SameValuesWhateverTheThreadCountAndSeed) {
  Instance g = height_field(12, 0.4f);
  g.texcoords.emplace_back();
  for (const Vec3& p : g.positions) g.texcoords[0].push_back({p.x / 4.4f, p.y / 4.4f});
  const auto s = scene_of({g});
  Options o;
  o.samples = 32;
  o.seed = 5;
  TextureOptions t = size(24, 20, 3);
  t.texel_samples = 4;
  TextureBake one;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = bake_one(s, o, t);
  }
  EXPECT_EQ(one.values, bake_one(s, o, t).values);
  o.seed = 6;
  EXPECT_NE(one.values, bake_one(s, o, t).values);
}

bool same_points(const texels::Coverage& a, const texels::Coverage& b) {
  if (a.points.size() != b.points.size()) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const texels::SurfacePoint &p = a.points[i], &q = b.points[i];
    if (p.texel != q.texel || p.instance != q.instance || p.triangle != q.triangle || p.x != q.x || p.y != q.y) return false;
  }
  return true;
}

// Coverage is rasterized in chunks of triangles in parallel: two height fields of 9,800 triangles
// each (several chunks apiece), the second mirrored over the first and shifted by a third of a
// texel (overlaps, and touched texels along every island edge), give the same points in the same
// order on one thread and on all, sorted by texel and, within a texel, in scene order.
TEST(TextureAo, CoverageIsTheSameOnAnyNumberOfThreads) {
  constexpr int kN = 71;
  Instance g = height_field(kN, 0.1f);
  add_grid_uvs(g, kN, {0.05f, 0.1f}, {0.8f / kN, 0.7f / kN});
  Instance mirrored = g;
  for (auto& uv : mirrored.texcoords[0]) uv = {0.9f - uv.x + 1.0f / 300, uv.y};
  const auto s = scene_of({g, mirrored});
  const TextureTarget target{{0, 1}};
  texels::Coverage one;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = *texels::cover(s, target, 100, 100);
  }
  const texels::Coverage all = *texels::cover(s, target, 100, 100);
  EXPECT_TRUE(same_points(one, all));
  EXPECT_EQ(one.triangles, 2u * 2 * (kN - 1) * (kN - 1));
  EXPECT_EQ(all.covered, one.covered);
  EXPECT_EQ(all.touched, one.touched);
  EXPECT_GT(one.overlapped, 0u);
  EXPECT_GT(one.touched, 0u);
  for (std::size_t i = 1; i < one.points.size(); ++i) {
    const texels::SurfacePoint &p = one.points[i - 1], &q = one.points[i];
    ASSERT_TRUE(p.texel < q.texel || (p.texel == q.texel && (p.instance < q.instance ||
                                                             (p.instance == q.instance && p.triangle < q.triangle))))
        << i;
  }
}

// Per texel, the number of surface points coverage gives it by its definition, by brute force over
// every unwrapped cell within reach of every triangle, in float64 with signed distances: the
// triangles whose UV image holds the centre (wrapped copies each), else one where a triangle lies
// within half a texel diagonal; −1 where a centre lies within 1e-9 of an edge or of that reach (the
// tie rule decides those, tested above).
std::vector<int> brute_force_points(const Instance& g, const TextureTarget& target, int width, int height) {
  const double reach = std::sqrt(0.5);
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  std::vector<int> inside(texels, 0);
  std::vector<double> nearest(texels, 1e300);
  std::vector<bool> ambiguous(texels, false);
  for (std::size_t t = 0; t < g.triangles.size(); ++t) {
    const texels::UvTriangle tri = texels::uv_triangle(g, target, t, width, height);
    const glm::dvec2 ab = tri.b - tri.a, ac = tri.c - tri.a;
    const double sign = ab.x * ac.y - ab.y * ac.x > 0 ? 1 : -1;
    const double x0 = std::min({tri.a.x, tri.b.x, tri.c.x}), x1 = std::max({tri.a.x, tri.b.x, tri.c.x});
    const double y0 = std::min({tri.a.y, tri.b.y, tri.c.y}), y1 = std::max({tri.a.y, tri.b.y, tri.c.y});
    for (double j = std::ceil(y0 - reach); j <= y1 + reach; ++j) {
      for (double i = std::ceil(x0 - reach); i <= x1 + reach; ++i) {
        const std::size_t texel = std::size_t(wrapped_index((long long)j, height, target.wrap_t) * width +
                                              wrapped_index((long long)i, width, target.wrap_s));
        const glm::dvec2 centre(i, j);
        const auto side = [&](const glm::dvec2& a, const glm::dvec2& b) {
          const glm::dvec2 d = b - a, q = centre - a;
          return sign * (d.x * q.y - d.y * q.x) / glm::length(d);  // signed distance, inside positive
        };
        const double e = std::min({side(tri.a, tri.b), side(tri.b, tri.c), side(tri.c, tri.a)});
        const glm::dvec3 w = texels::nearest_weights(tri, centre);
        const double distance = glm::length(w.x * tri.a + w.y * tri.b + w.z * tri.c - centre);
        ambiguous[texel] = ambiguous[texel] || std::abs(e) < 1e-9 || std::abs(distance - reach) < 1e-9;
        inside[texel] += e > 0;
        nearest[texel] = std::min(nearest[texel], distance);
      }
    }
  }
  std::vector<int> expected(texels);
  for (std::size_t k = 0; k < texels; ++k) {
    expected[k] = ambiguous[k] ? -1 : inside[k] > 0 ? inside[k] : nearest[k] <= reach ? 1 : 0;
  }
  return expected;
}

// Coverage against the brute force: its points per texel, sorted by texel and within a texel by
// triangle. Returns how many texels were compared.
std::size_t expect_brute_force_coverage(const Instance& g, const TextureTarget& target, int width, int height,
                                        const std::string& label) {
  const auto coverage = texels::cover(scene_of({g}), target, width, height);
  EXPECT_TRUE(coverage) << label;
  if (!coverage) return 0;
  std::vector<int> points(std::size_t(width * height), 0);
  for (std::size_t k = 0; k < coverage->points.size(); ++k) {
    const texels::SurfacePoint& p = coverage->points[k];
    ++points[p.texel];
    if (k > 0) {
      const texels::SurfacePoint& q = coverage->points[k - 1];
      EXPECT_TRUE(q.texel < p.texel || (q.texel == p.texel && q.triangle <= p.triangle)) << label << ": point " << k;
    }
  }
  const std::vector<int> expected = brute_force_points(g, target, width, height);
  std::size_t compared = 0;
  for (std::size_t k = 0; k < expected.size(); ++k) {
    if (expected[k] < 0) continue;
    ++compared;
    EXPECT_EQ(points[k], expected[k]) << label << ": texel " << k % std::size_t(width) << ", " << k / std::size_t(width);
    if (points[k] != expected[k]) break;
  }
  return compared;
}

// A jittered grid of large triangles (rows rasterized by their crossings) and one of small ones
// (scanned cell by cell), each also mirrored, in a non-square texture of 2 × 2 tiles (the last cut).
TEST(TextureAo, CoverageMatchesABruteForce) {
  const int width = 61, height = 47;
  std::mt19937 random(7);
  for (const auto& [n, mirrored] : {std::pair{4, false}, {4, true}, {13, false}, {13, true}, {29, false}}) {
    Instance g = height_field(n, 0.3f);
    std::uniform_real_distribution<float> jitter(-0.3f / float(n), 0.3f / float(n));
    add_grid_uvs(g, n, {0.08f, 0.11f}, {0.84f / float(n - 1), 0.8f / float(n - 1)});
    for (glm::vec2& uv : g.texcoords[0]) {
      uv += glm::vec2(jitter(random), jitter(random));
      if (mirrored) uv.x = 1 - uv.x;
    }
    const std::string label = std::to_string(n) + (mirrored ? " mirrored" : "");
    EXPECT_GT(expect_brute_force_coverage(g, TextureTarget{{0}}, width, height, label), std::size_t(width * height) * 9 / 10);
  }
}

// UVs over three copies of the texture each way (-1.3 to 1.8), wrapped in each mode: each copy's
// points land on the texel they wrap to (clamped ones on the edge texels, many a texel), the same
// as the brute force's, in textures whose sides are not whole tiles. Large triangles and small.
TEST(TextureAo, WrappedCoverageMatchesABruteForceInEveryWrapMode) {
  std::mt19937 random(11);
  for (const Wrap wrap : {Wrap::repeat, Wrap::mirrored_repeat, Wrap::clamp_to_edge}) {
    for (const auto& [n, width, height] : {std::tuple{5, 45, 37}, {17, 70, 33}}) {
      Instance g = height_field(n, 0.3f);
      std::uniform_real_distribution<float> jitter(-0.3f / float(n), 0.3f / float(n));
      add_grid_uvs(g, n, {-1.3f, -1.1f}, {3.1f / float(n - 1), 2.9f / float(n - 1)});
      for (glm::vec2& uv : g.texcoords[0]) uv += glm::vec2(jitter(random), jitter(random));
      TextureTarget target{{0}};
      target.wrap_s = target.wrap_t = wrap;
      const std::string label = "wrap " + std::to_string(int(wrap)) + ", " + std::to_string(n);
      EXPECT_GT(expect_brute_force_coverage(g, target, width, height, label), std::size_t(width * height) * 8 / 10) << label;
    }
  }
}

// The cap on surface points holds exactly, below and above the batches in which the parallel
// chunks count them: 5 stacked copies of a plane over 64 × 64 texels map 20,480 centres.
TEST(TextureAo, CoverageRefusesMoreSurfacePointsThanItsCap) {
  std::vector<Instance> copies(5, square({0, 0, 0}, kX, kY, 1));
  for (std::size_t k = 1; k < copies.size(); ++k) {
    for (Vec3& p : copies[k].positions) p.z = float(k);
  }
  const auto s = scene_of(copies);
  const TextureTarget target{{0, 1, 2, 3, 4}};
  const auto exact = texels::cover(s, target, 64, 64, 20480);
  ASSERT_TRUE(exact);
  EXPECT_EQ(exact->points.size(), 20480u);
  EXPECT_EQ(exact->overlapped, 4096u);
  for (std::size_t cap : {std::size_t{20479}, std::size_t{5000}, std::size_t{10}}) {
    const auto over = texels::cover(s, target, 64, 64, cap);
    ASSERT_FALSE(over) << cap;
    EXPECT_NE(over.error().to_string().find("more than " + std::to_string(cap) + " surface points"), std::string::npos)
        << over.error().to_string();
  }
}

// Padding: the nearest mapped texel's value, ties averaged, against a float64 brute force on a
// random mask; nothing beyond the padding changes.
TEST(TextureAo, PaddingTakesTheNearestMappedTexelTiesAveraged) {
  std::vector<float> line = {0.2f, 1, 1, 1, 0.6f, 1, 1, 1};
  EXPECT_EQ(texels::pad(line, {true, false, false, false, true, false, false, false}, 8, 1, 2), 5u);
  EXPECT_EQ(line, (std::vector<float>{0.2f, 0.2f, 0.4f, 0.6f, 0.6f, 0.6f, 0.6f, 1}));
  std::mt19937 random(3);
  const int w = 37, h = 23, padding = 4;
  std::vector<float> values(w * h, 1.0f);
  std::vector<bool> mapped(w * h, false);
  for (int i = 0; i < 12; ++i) {
    const std::size_t k = random() % std::size_t(w * h);
    mapped[k] = true;
    values[k] = float(random() % 1000) / 1000;
  }
  std::vector<float> padded = values;
  const std::size_t count = texels::pad(padded, mapped, w, h, padding);
  std::size_t expected_count = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (mapped[std::size_t(y * w + x)]) continue;
      long best = padding * padding + 1;
      double sum = 0;
      int ties = 0;
      for (int yy = 0; yy < h; ++yy) {
        for (int xx = 0; xx < w; ++xx) {
          if (!mapped[std::size_t(yy * w + xx)]) continue;
          const long d = long(xx - x) * (xx - x) + long(yy - y) * (yy - y);
          if (d > padding * padding) continue;
          if (d < best) best = d, sum = 0, ties = 0;
          if (d == best) sum += values[std::size_t(yy * w + xx)], ++ties;
        }
      }
      const float expected = ties ? float(sum / ties) : 1.0f;
      expected_count += ties ? 1 : 0;
      EXPECT_FLOAT_EQ(padded[std::size_t(y * w + x)], expected) << x << "," << y;
    }
  }
  EXPECT_EQ(count, expected_count);
}

// The nearest mapped texel of every texel, however far: at the brute force's least distance, on
// random masks from one mapped texel to many; none mapped, none found.
TEST(TextureAo, NearestMappedTexelIsAtTheLeastDistance) {
  std::mt19937 random(5);
  const int w = 41, h = 29;
  for (const int sites : {1, 3, 40, 600}) {
    std::vector<bool> mapped(w * h, false);
    for (int i = 0; i < sites; ++i) mapped[random() % std::size_t(w * h)] = true;
    const std::vector<std::int64_t> nearest = texels::nearest_mapped(mapped, w, h);
    for (int t = 0; t < w * h; ++t) {
      long best = std::numeric_limits<long>::max();
      for (int s = 0; s < w * h; ++s) {
        if (mapped[std::size_t(s)]) best = std::min(best, long(s % w - t % w) * (s % w - t % w) + long(s / w - t / w) * (s / w - t / w));
      }
      const std::int64_t n = nearest[std::size_t(t)];
      ASSERT_TRUE(n >= 0 && mapped[std::size_t(n)]) << sites << " sites, texel " << t;
      EXPECT_EQ(long(n % w - t % w) * (n % w - t % w) + long(n / w - t / w) * (n / w - t / w), best) << sites << " sites, texel " << t;
    }
  }
  EXPECT_EQ(texels::nearest_mapped(std::vector<bool>(12, false), 4, 3), std::vector<std::int64_t>(12, -1));
}

// The same for a list of wanted texels: a few near mapped ones (searched ring by ring), many, or
// one far from every mapped texel (the transform's answer), each at the brute force's least distance.
TEST(TextureAo, NearestMappedToWantedTexelsIsAtTheLeastDistance) {
  std::mt19937 random(7);
  const int w = 97, h = 83;
  const auto squared = [&](std::int64_t a, std::int64_t b) {
    return long(a % w - b % w) * (a % w - b % w) + long(a / w - b / w) * (a / w - b / w);
  };
  for (const int sites : {1, 5, 300, 4000}) {
    std::vector<bool> mapped(w * h, false);
    for (int i = 0; i < sites; ++i) mapped[random() % std::size_t(w * h)] = true;
    for (const std::size_t count : {std::size_t(1), std::size_t(10), std::size_t(w * h / 8)}) {
      std::vector<std::size_t> wanted;
      for (std::size_t i = 0; i < count; ++i) wanted.push_back(random() % std::size_t(w * h));
      const std::vector<std::int64_t> nearest = texels::nearest_mapped_to(mapped, w, h, wanted);
      ASSERT_EQ(nearest.size(), wanted.size());
      for (std::size_t i = 0; i < wanted.size(); ++i) {
        long best = std::numeric_limits<long>::max();
        for (int s = 0; s < w * h; ++s) {
          if (mapped[std::size_t(s)]) best = std::min(best, squared(s, std::int64_t(wanted[i])));
        }
        ASSERT_TRUE(nearest[i] >= 0 && mapped[std::size_t(nearest[i])]) << sites << " sites, texel " << wanted[i];
        ASSERT_EQ(squared(nearest[i], std::int64_t(wanted[i])), best) << sites << " sites, " << count << " wanted, texel " << wanted[i];
      }
    }
  }
  EXPECT_EQ(texels::nearest_mapped_to(std::vector<bool>(12, false), 4, 3, {0, 5, 11}), std::vector<std::int64_t>(3, -1));
}

TEST(TextureAo, PaddingDefaultsAndBadOptions) {
  EXPECT_EQ(padding_for(size(1024, 1024, -1)), 16);
  EXPECT_EQ(padding_for(size(4096, 512, -1)), 64);
  EXPECT_EQ(padding_for(size(16, 16, -1)), 1);
  EXPECT_EQ(padding_for(size(16, 16, 0)), 0);
  const auto s = scene_of({square({0, 0, 0}, kX, kY, 1)});
  for (TextureOptions bad : {size(0, 4), size(4, -1), size(kMaxTextureSide + 1, 1), size(4, 4, -2)}) {
    EXPECT_FALSE(bake_textures(s, Options{}, {{{0}}}, bad));
  }
  TextureOptions too_many = size(4, 4);
  too_many.texel_samples = 65;
  EXPECT_FALSE(bake_textures(s, Options{}, {{{0}}}, too_many));
  EXPECT_FALSE(bake_textures(s, Options{}, {{{3}}}, size(4, 4)));
}

// Padding fills the border around an island (a 2×2 quad in the middle of a 16×16 texture) from its
// texels; the rest keeps 1.
TEST(TextureAo, PaddingAroundAnIslandInABake) {
  Instance small = square({0, 0, 0}, kX, kY, 1);
  for (auto& uv : small.texcoords[0]) uv = glm::vec2(0.375f) + uv * 0.25f;  // texels 6..9
  Instance ceiling = square({0, 0, 1}, kY, kX, 1000);
  ceiling.texcoords.clear();
  const TextureBake t = bake_one(scene_of({small, ceiling}), binary(64, 2), size(16, 16, 2));
  EXPECT_EQ(t.covered, 16u);  // texels 6..9: the island's edges lie on texel borders
  EXPECT_EQ(t.touched, 20u);  // the ring 5..10 around them, corners included (√½ away)
  // Two texels around that ring, Euclidean: the 3 texels of each outer corner are more than 2 away.
  EXPECT_EQ(t.padded, 10u * 10u - 36u - 4u * 3u);
  EXPECT_EQ(t.values[0], 1.0f);
  EXPECT_EQ(t.values[std::size_t(4 * 16 + 4)], t.values[std::size_t(6 * 16 + 6)]);  // the corner's diagonal
}

}  // namespace
}  // namespace matbake::ao
