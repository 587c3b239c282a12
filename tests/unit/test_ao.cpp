// Ambient obscurance against closed forms (tolerance: 3σ of the binary estimator at the sample
// count, or tighter where the answer is exact), scale invariance, determinism, and the gain of the
// low-discrepancy sampler.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "lib/src/ao/sequence.hpp"
#include "matbake/ao.hpp"
#include "support/ao_scenes.hpp"

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

constexpr float kHalf = 1000;

Options binary(int samples) {
  Options o;
  o.samples = samples;
  o.falloff = Falloff::none;
  o.absolute_distance = 1e5;
  return o;
}

float centre_value(const scene::Scene& s, const Options& o, std::size_t instance = 0) {
  auto r = bake(s, o);
  EXPECT_TRUE(r) << r.error().to_string();
  return r->values[instance][0];
}

TEST(AmbientOcclusion, IsolatedPlaneAndConvexMeshAreExactlyOpen) {
  for (Falloff f : {Falloff::none, Falloff::exponential}) {
    Options o = binary(256);
    o.falloff = f;
    auto open = bake(scene_of({square({0, 0, 0}, kX, kY, 1)}), o);
    ASSERT_TRUE(open);
    for (float w : open->values[0]) EXPECT_EQ(w, 1.0f);
    // A cube with outward faces: no vertex may see its own mesh (the self-intersection test).
    std::vector<Instance> faces = {square({0, 0, 1}, kX, kY, 1),  square({0, 0, -1}, kY, kX, 1),
                                   square({1, 0, 0}, kY, kZ, 1),  square({-1, 0, 0}, kZ, kY, 1),
                                   square({0, 1, 0}, kZ, kX, 1),  square({0, -1, 0}, kX, kZ, 1)};
    auto cube = bake(scene_of(faces), o);
    ASSERT_TRUE(cube);
    for (const auto& face : cube->values) EXPECT_EQ(face[0], 1.0f);
  }
}

TEST(AmbientOcclusion, PlaneUnderAParallelPlaneIsOneMinusTwoE3) {
  const double h = 1, tau = 1;  // τh = 1
  // E3(z) = ∫_0^1 e^(−z/μ) μ dμ, midpoint rule in float64.
  double e3 = 0;
  constexpr int kSteps = 200000;
  for (int i = 0; i < kSteps; ++i) {
    const double mu = (i + 0.5) / kSteps;
    e3 += std::exp(-tau * h / mu) * mu / kSteps;
  }
  const double expected = 1 - 2 * e3;  // 0.7806
  Options o;
  o.samples = 4096;
  o.absolute_distance = 1e4;  // effectively unbounded: μ(x) = 1 − e^(−τx)
  o.tau = tau * o.absolute_distance;
  const auto s = scene_of({square({0, 0, 0}, kX, kY, kHalf), square({0, 0, float(h)}, kY, kX, kHalf)});
  // μ is continuous: σ ≤ 0.5/√N; the large quads lose at most e^(−τ·1000)-ish of the integral.
  EXPECT_NEAR(centre_value(s, o), expected, 3 * 0.5 / std::sqrt(4096.0));
}

TEST(AmbientOcclusion, FootOfAWallAndCorners) {
  const int n = 4096;
  const float gap = 1e-3f;  // the walls stand just behind the probe, off its plane
  const Instance floor = square({0, 0, 0}, kX, kY, kHalf);
  const Instance wall_x = square({-gap, 0, kHalf}, kY, kZ, kHalf);
  const Instance wall_y = square({0, -gap, kHalf}, kZ, kX, kHalf);
  EXPECT_NEAR(centre_value(scene_of({floor, wall_x}), binary(n)), 0.5, three_sigma(0.5, n));
  EXPECT_NEAR(centre_value(scene_of({floor, wall_x, wall_y}), binary(n)), 0.25, three_sigma(0.25, n));
  // The same corner seen with the normal (1, 1, 1)/√3: cosine weighting gives √3/4.
  Instance probe;
  const Vec3 diagonal = glm::normalize(Vec3(1, 1, 1));
  probe.positions = {{gap, gap, gap}, Vec3(gap) + 1e-4f * glm::normalize(Vec3(1, -1, 0)),
                     Vec3(gap) + 1e-4f * glm::normalize(Vec3(1, 1, -2))};
  probe.triangles = {{0, 1, 2}};
  probe.normals = {diagonal, diagonal, diagonal};
  Instance floor_low = square({0, 0, -gap}, kX, kY, kHalf);
  EXPECT_NEAR(centre_value(scene_of({probe, floor_low, wall_x, wall_y}), binary(n)), std::sqrt(3.0) / 4,
              three_sigma(0.433, n));
}

TEST(AmbientOcclusion, InsideAClosedSphereIsDark) {
  // A UV sphere wound inwards: its vertices look at its inside.
  Instance sphere;
  constexpr int kRings = 16, kSegments = 32;
  for (int i = 0; i <= kRings; ++i) {
    for (int j = 0; j < kSegments; ++j) {
      const float theta = std::numbers::pi_v<float> * float(i) / kRings, phi = 2 * std::numbers::pi_v<float> * float(j) / kSegments;
      sphere.positions.push_back({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  }
  for (int i = 0; i < kRings; ++i) {
    for (int j = 0; j < kSegments; ++j) {
      const auto at = [](int r, int s) { return std::uint32_t(r * kSegments + (s % kSegments)); };
      sphere.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)});
      sphere.triangles.push_back({at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
    }
  }
  Options o = binary(256);
  o.absolute_distance = 10;
  auto r = bake(scene_of({sphere}), o);
  ASSERT_TRUE(r);
  for (std::size_t v = kSegments; v < sphere.positions.size() - kSegments; ++v) EXPECT_EQ(r->values[0][v], 0.0f) << v;
}

TEST(AmbientOcclusion, ScaleInvariantWithARelativeRange) {
  const auto make = [](float scale) {
    return scene_of({square({0, 0, 0}, kX, kY, 10 * scale), square({-0.5f * scale, 0, 5 * scale}, kY, kZ, 5 * scale)});
  };
  Options o;
  o.samples = 256;
  o.relative_distance = 0.3;
  const auto reference = bake(make(1), o);
  ASSERT_TRUE(reference);
  for (float scale : {1e-3f, 1e3f}) {
    const auto scaled = bake(make(scale), o);
    ASSERT_TRUE(scaled);
    for (std::size_t k = 0; k < 2; ++k) {
      for (std::size_t v = 0; v < scaled->values[k].size(); ++v) {
        EXPECT_NEAR(scaled->values[k][v], reference->values[k][v], 1e-4) << scale;
      }
    }
  }
}

TEST(AmbientOcclusion, SameValuesWhateverTheThreadCount) {
  std::vector<Instance> grid;
  for (int i = 0; i < 40; ++i) grid.push_back(square({float(i), 0, float(i % 3)}, kX, kY, 0.7f));
  const auto s = scene_of(grid);
  Options o;
  o.samples = 64;
  o.seed = 7;
  o.two_sided = true;  // the squares above show their backs
  Bake one;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = *bake(s, o);
  }
  EXPECT_EQ(one.values, bake(s, o)->values);
  o.seed = 8;
  EXPECT_NE(one.values, bake(s, o)->values);
}

TEST(AmbientOcclusion, LowDiscrepancyBeatsRandomAtEqualSamples) {
  const auto s = scene_of({square({0, 0, 0}, kX, kY, kHalf), square({-1e-3f, 0, kHalf}, kY, kZ, kHalf)});
  double sobol = 0, random = 0;
  for (std::uint64_t seed = 0; seed < 64; ++seed) {
    Options o = binary(64);
    o.seed = seed;
    sobol += std::pow(centre_value(s, o) - 0.5, 2);
    o.sampler = Sampler::random;
    random += std::pow(centre_value(s, o) - 0.5, 2);
  }
  EXPECT_LT(std::sqrt(sobol / 64), 0.5 * std::sqrt(random / 64));
}

// A box of half-size `half` around `center` as one mesh of 24 vertices, each corner three times, and one more.
// Outwards: each with its face's own normal (flat shading: same position, different normals).
// Inwards: each with the corner's diagonal towards the centre (a flat-shaded inner corner would
// start its rays exactly on the two neighbouring faces' planes, where rounding decides). Two
// degenerate triangles are added: one with a repeated index, one with three collinear corners.
Instance flat_box(const Vec3& center, float half, bool inward) {
  Instance box;
  const Vec3 axes[3] = {kX, kY, kZ};
  for (int a = 0; a < 3; ++a) {
    for (float side : {1.0f, -1.0f}) {
      const Vec3 n = side * axes[a], u = axes[(a + 1) % 3], v = side * axes[(a + 2) % 3];  // u × v = n
      const auto first = std::uint32_t(box.positions.size());
      for (const auto& [su, sv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        box.positions.push_back(center + half * (n + float(su) * u + float(sv) * v));
        box.normals.push_back(inward ? glm::normalize(center - box.positions.back()) : n);
      }
      const std::array<std::uint32_t, 3> t0 = {first, first + 1, first + 2}, t1 = {first, first + 2, first + 3};
      box.triangles.push_back(inward ? std::array{t0[0], t0[2], t0[1]} : t0);
      box.triangles.push_back(inward ? std::array{t1[0], t1[2], t1[1]} : t1);
    }
  }
  box.triangles.push_back({0, 0, 1});
  box.positions.push_back(0.5f * (box.positions[0] + box.positions[1]));  // on the edge from corner 0 to 1
  box.normals.push_back(box.normals[0]);
  box.triangles.push_back({0, 24, 1});
  return box;
}

// Meshes 1e-4 and 1e4 across in one scene: the ray origin offset follows each mesh's own edges and
// coordinates, not the scene's size.
TEST(AmbientOcclusion, SharedCornersDegenerateFacesAndMixedScales) {
  Options o = binary(256);
  o.absolute_distance = 1e3;  // the boxes, 2.5e4 apart, do not see each other
  const auto outside = scene_of({flat_box({0, 0, 0}, 5e-5f, false), flat_box({3e4f, 0, 0}, 5e3f, false)});
  auto open = bake(outside, o);
  ASSERT_TRUE(open);
  for (std::size_t k = 0; k < 2; ++k) {
    for (std::size_t v = 0; v < 25; ++v) EXPECT_EQ(open->values[k][v], 1.0f) << "box " << k << " vertex " << v;
  }
  // Inside a closed box nothing is open: no ray may leak out through an edge or a corner.
  o.absolute_distance = 1e6;
  const auto inside = scene_of({flat_box({0, 0, 0}, 5e-5f, true), flat_box({3e4f, 0, 0}, 5e3f, true)});
  auto closed = bake(inside, o);
  ASSERT_TRUE(closed);
  for (std::size_t k = 0; k < 2; ++k) {
    for (std::size_t v = 0; v < 25; ++v) EXPECT_EQ(closed->values[k][v], 0.0f) << "box " << k << " vertex " << v;
  }
}

TEST(AmbientOcclusion, CoplanarOverlapsDoNotOcclude) {
  // Two copies of the same square, one shifted within the plane, one facing the other way.
  const auto s = scene_of({square({0, 0, 0}, kX, kY, 1), square({0.3f, 0.2f, 0}, kX, kY, 1), square({0, 0, 0}, kY, kX, 1)});
  auto r = bake(s, binary(256));
  ASSERT_TRUE(r);
  EXPECT_EQ(r->values[0][0], 1.0f);
  EXPECT_EQ(r->values[1][0], 1.0f);
  EXPECT_EQ(r->values[2][0], 1.0f);  // its hemisphere is below: nothing there either
}

TEST(AmbientOcclusion, VertexInNoFaceAndOneSidedSurfaces) {
  // A floor facing +z; below it a mesh with one small triangle far away and one vertex in no face,
  // which takes the mesh's face normal (+z) and so looks up at the floor's back.
  Instance below;
  below.positions = {{0, 0, -1}, {50, 50, -1}, {50.1f, 50, -1}, {50, 50.1f, -1}};
  below.triangles = {{1, 2, 3}};
  const auto s = scene_of({square({0, 0, 0}, kX, kY, kHalf), below});
  Options o = binary(256);
  o.two_sided = true;
  auto two = bake(s, o);
  ASSERT_TRUE(two);
  EXPECT_EQ(two->values[1][0], 0.0f);  // misses only within 1e-6 of the horizon
  o.two_sided = false;
  auto one = bake(s, o);
  ASSERT_TRUE(one);
  EXPECT_EQ(one->values[1][0], 1.0f);  // the floor's back does not occlude
}

TEST(AmbientOcclusion, BadOptions) {
  const auto s = scene_of({square({0, 0, 0}, kX, kY, 1)});
  Options o;
  o.samples = 0;
  EXPECT_FALSE(bake(s, o));
  o = Options{};
  o.absolute_distance = -1;
  EXPECT_FALSE(bake(s, o));
  o = Options{};
  o.relative_distance = std::nan("");
  EXPECT_FALSE(bake(s, o));
  o = Options{};
  o.samples = kMaxSamples + 1;
  EXPECT_FALSE(bake(s, o));
}

// Sobol's second dimension has the Pascal matrix mod 2 as generator (Joe and Kuo): bit k of the
// index adds the bits 31 − j of the result for every j ≤ k with C(k, j) odd, that is j ⊆ k (Lucas).
// Every single bit, and indices that use all four bytes, against that definition.
std::uint32_t sobol_second_from_pascal(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t k = 0; k < 32; ++k) {
    if (!((i >> k) & 1)) continue;
    for (std::uint32_t j = 0; j <= k; ++j) {
      if ((j & k) == j) r ^= 1u << (31 - j);
    }
  }
  return r;
}

TEST(AoSequence, SobolSecondDimensionIsThePascalMatrix) {
  std::vector<std::uint32_t> indices = {0, 0xffffffffu, 0x80000001u, 0x12345678u, 0xdeadbeefu, 0x00ff00ffu};
  for (std::uint32_t k = 0; k < 32; ++k) indices.push_back(1u << k);
  for (std::uint32_t i = 0; i < 4096; ++i) indices.push_back(i * 0x9e3779b9u);
  for (std::uint32_t i : indices) ASSERT_EQ(sobol_second(i), sobol_second_from_pascal(i)) << i;
}

// The first 2^m samples of any scramble are a (0, m, 2)-net: every box [a/2^k, (a+1)/2^k) ×
// [b/2^(m−k), (b+1)/2^(m−k)) holds exactly one (a scramble XORs the same bits into every
// sample, which permutes the boxes); and a point's Sequence gives sample()'s values.
TEST(AoSequence, SobolSamplesAreZeroMTwoNetsWhateverTheScramble) {
  constexpr int m = 10, n = 1 << m;
  for (std::uint64_t key : {0ull, 1ull, 0x9e3779b97f4a7c15ull}) {
    const Sequence sequence(Sampler::sobol, key);
    for (int k = 0; k <= m; ++k) {
      std::vector<int> boxes(n, 0);
      for (std::uint32_t i = 0; i < std::uint32_t(n); ++i) {
        const Sample2 u = sequence[i];
        ASSERT_EQ(u.u, sample(Sampler::sobol, i, key).u);
        ASSERT_EQ(u.v, sample(Sampler::sobol, i, key).v);
        const int a = int(u.u * float(1 << k)), b = int(u.v * float(1 << (m - k)));
        ++boxes[std::size_t(a * (1 << (m - k)) + b)];
      }
      EXPECT_EQ(*std::max_element(boxes.begin(), boxes.end()), 1) << "key " << key << ", k " << k;
    }
  }
}

// unit_circle against cos and sin in double at 2^20 + 1 points over [0, 1) and next to each
// quarter turn (where the reduction switches), within the bound its header states.
TEST(AoSequence, UnitCircleIsWithinTwoTenMillionthsOfCosAndSin) {
  std::vector<float> at;
  for (int i = 0; i < (1 << 20); ++i) at.push_back(float(i) / float(1 << 20));
  for (float quarter : {0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, 1.0f}) {
    at.push_back(std::nextafter(quarter, 0.0f));
    if (quarter < 1) at.push_back(std::nextafter(quarter, 1.0f));
  }
  double worst = 0;
  for (float v : at) {
    const auto [c, s] = unit_circle(v);
    const double angle = 2 * std::numbers::pi * double(v);
    worst = std::max({worst, std::abs(double(c) - std::cos(angle)), std::abs(double(s) - std::sin(angle))});
  }
  EXPECT_LT(worst, 2e-7);
}

}  // namespace
}  // namespace matbake::ao
