// The high-to-low bake (matbake/bake.hpp) against closed forms: a hemispherical bump on a plane
// (height and normal of the high-poly's own surface at each texel, in the plane's tangent basis,
// both green conventions) and a tessellated sphere onto an icosphere, smooth and flat, rotated and
// moved (each texel's normal, decoded with the runtime's rule, is the sphere's normal at the hit;
// the hit lies on the texel's cage ray and on the tessellated sphere). Float64 references; the
// tolerances are float32's precision or the 8-bit step, derived below.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "lib/src/bake/frames.hpp"
#include "matbake/bake.hpp"
#include "support/shapes.hpp"

namespace matbake::bake {
namespace {

using glm::dvec3;

// An instance whose object space is `world`'s preimage: positions and normals given in object
// space, carried to world space as the scene loader does.
scene::Instance placed(const std::vector<dvec3>& positions, const std::vector<dvec3>& normals,
                       std::vector<std::array<std::uint32_t, 3>> triangles, const glm::dmat4& world) {
  scene::Instance inst;
  inst.world = world;
  inst.triangles = std::move(triangles);
  if (glm::determinant(glm::dmat3(world)) < 0) {  // as the loader keeps a mirrored node's facing
    for (auto& t : inst.triangles) std::swap(t[1], t[2]);
  }
  const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(world)));
  for (std::size_t v = 0; v < positions.size(); ++v) {
    inst.object.positions.emplace_back(positions[v]);
    inst.positions.emplace_back(world * glm::dvec4(positions[v], 1));
    if (normals.empty()) continue;
    inst.object.normals.emplace_back(normals[v]);
    inst.normals.emplace_back(glm::normalize(normal_matrix * normals[v]));
  }
  return inst;
}

scene::Scene scene_of(std::vector<scene::Instance> instances) {
  scene::Scene s;
  s.instances = std::move(instances);
  s.bounds_min = s.bounds_max = s.instances[0].positions[0];
  for (const auto& inst : s.instances) {
    for (const auto& p : inst.positions) s.bounds_min = glm::min(s.bounds_min, p), s.bounds_max = glm::max(s.bounds_max, p);
  }
  return s;
}

const MapImage& map_of(const TextureBake& t, Map map) {
  for (const MapImage& m : t.maps) {
    if (m.map == map) return m;
  }
  throw std::runtime_error("map not baked");
}
dvec3 texel3(const MapImage& m, std::size_t texel) {
  const float* v = &m.values[3 * texel];
  return dvec3(v[0], v[1], v[2]);
}

// The plane z = 0 over [-1, 1]², two triangles, u = (x + 1)/2, v = (1 - y)/2: up the texture is +y,
// so glTF's tangent basis is T = +x, B = +y, N = +z and a normal (x, y, z) is stored as itself.
// The high-poly: an n × n grid over the same square, lifted onto a hemisphere of radius r at the
// origin (z = √(r² − x² − y²) inside it) with the sphere's normals there, +z outside.
struct BumpPair {
  scene::Scene low, high;
  int n;
  double r;
};
BumpPair bump_pair(int n, double r) {
  BumpPair pair{scene_of({placed({{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
                                 {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1))}),
                {}, n, r};
  scene::Instance& low = pair.low.instances[0];
  low.texcoords.push_back({{0, 1}, {1, 1}, {1, 0}, {0, 0}});
  std::vector<dvec3> positions, normals;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n, d2 = x * x + y * y;
      const double z = d2 < r * r ? std::sqrt(r * r - d2) : 0;
      positions.emplace_back(x, y, z);
      normals.push_back(d2 < r * r ? dvec3(x, y, z) / r : dvec3(0, 0, 1));
    }
  }
  std::vector<std::array<std::uint32_t, 3>> triangles;
  const auto at = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  pair.high = scene_of({placed(positions, normals, triangles, glm::dmat4(1))});
  return pair;
}

// The high-poly bump's surface over (x, y), in float64: the grid triangle holding the point, its
// barycentric weights, height and interpolated normal (normalized).
struct Surface {
  double z;
  dvec3 normal;
};
Surface bump_surface(const BumpPair& pair, double x, double y) {
  const scene::Instance& high = pair.high.instances[0];
  const double s = (x + 1) / 2 * pair.n, t = (y + 1) / 2 * pair.n;
  const int i = std::min(int(s), pair.n - 1), j = std::min(int(t), pair.n - 1);
  const double fx = s - i, fy = t - j;
  const std::size_t cell = 2 * std::size_t(j * pair.n + i);
  // Lower triangle (i,j) (i+1,j) (i+1,j+1) where fx ≥ fy; upper (i,j) (i+1,j+1) (i,j+1).
  const auto& tri = high.triangles[fx >= fy ? cell : cell + 1];
  const dvec3 w = fx >= fy ? dvec3(1 - fx, fx - fy, fy) : dvec3(1 - fy, fx, fy - fx);
  Surface out{0, dvec3(0)};
  for (int k = 0; k < 3; ++k) {
    out.z += w[k] * double(high.positions[tri[std::size_t(k)]].z);
    out.normal += w[k] * dvec3(high.normals[tri[std::size_t(k)]]);
  }
  out.normal = glm::normalize(out.normal);
  return out;
}

TEST(Bake, ABumpOnAPlaneGivesTheHighPolysHeightAndNormalInThePlanesBasis) {
  const BumpPair pair = bump_pair(40, 0.5);
  for (const Green green : {Green::opengl, Green::directx}) {
    Options options;
    options.maps = {Map::normal, Map::height, Map::position};
    options.front = 0.75, options.back = 0.25, options.absolute_distances = true;
    options.green = green;
    ao::TextureOptions texture{.width = 64, .height = 64, .padding = 2, .texel_samples = 1};
    auto baked = bake(pair.low, pair.high, {ao::TextureTarget{{0}, 0}}, texture, options);
    ASSERT_TRUE(baked) << baked.error().message;
    const TextureBake& t = baked->textures.at(0);
    EXPECT_EQ(t.texels, 64u * 64u);
    EXPECT_EQ(t.misses, 0u);
    double lowest = 1, highest = 0;
    for (int j = 0; j < 64; ++j) {
      for (int i = 0; i < 64; ++i) {
        const double x = 2 * (i + 0.5) / 64 - 1, y = 1 - 2 * (j + 0.5) / 64;
        const Surface s = bump_surface(pair, x, y);
        lowest = std::min(lowest, s.z), highest = std::max(highest, s.z);
        const std::size_t texel = std::size_t(j * 64 + i);
        // float32: positions of magnitude 1 and distances of 0.75, a few ulps each.
        ASSERT_NEAR(map_of(t, Map::height).values[texel], s.z, 1e-6) << i << "," << j;
        const dvec3 p = texel3(map_of(t, Map::position), texel);
        ASSERT_NEAR(glm::length(p - dvec3(x, y, s.z)), 0, 1e-6) << i << "," << j;
        dvec3 want = s.normal;
        if (green == Green::directx) want.y = -want.y;
        const dvec3 got = texel3(map_of(t, Map::normal), texel) * 2.0 - 1.0;
        ASSERT_NEAR(glm::length(got - want), 0, 1e-6) << i << "," << j << " green " << int(green);
      }
    }
    EXPECT_NEAR(t.height_min, lowest, 1e-6);
    EXPECT_NEAR(t.height_max, highest, 1e-6);
  }
}

// The high-poly: the low-poly's plane 0.05 below it, the same UVs (its tangent basis T = +x,
// B = +y, N = +z), with a normal map of one code c = t/2 + ½, t = normalize(0.3, −0.2, 1). With
// high_normal_maps every texel's normal is t decoded (scale 1), and normalize(0.5·t.x, 0.5·t.y, t.z)
// at scale 0.5 (glTF's rule); without, the plane's own +z. Tolerance: float32 codes.
TEST(Bake, TheHighPolysNormalMapIsAppliedInItsTangentBasis) {
  const BumpPair pair = bump_pair(1, 0.5);
  scene::Instance high = pair.low.instances[0];
  for (auto* positions : {&high.positions, &high.object.positions}) {
    for (auto& p : *positions) p.z -= 0.05f;
  }
  high.material = 0;
  const dvec3 t = glm::normalize(dvec3(0.3, -0.2, 1));
  NormalTexture normal;
  normal.texture.image.width = normal.texture.image.height = 2, normal.texture.image.channels = 3;
  for (int k = 0; k < 4; ++k) {
    for (int c = 0; c < 3; ++c) normal.texture.image.pixels.push_back(float(t[c] * 0.5 + 0.5));
  }
  Options options;
  options.maps = {Map::normal};
  options.front = 0.1, options.back = 0.1, options.absolute_distances = true;
  const ao::TextureOptions texture{.width = 16, .height = 16, .texel_samples = 1};
  for (const double scale : {1.0, 0.5}) {
    for (const bool apply : {true, false}) {
      normal.scale = scale;
      options.high_normal_maps = apply;
      HighMaterials materials;
      materials.normals = {normal};
      auto baked = bake(pair.low, scene_of({high}), {ao::TextureTarget{{0}, 0}}, texture, options, {}, materials);
      ASSERT_TRUE(baked) << baked.error().message;
      const dvec3 want = apply ? glm::normalize(dvec3(scale * t.x, scale * t.y, t.z)) : dvec3(0, 0, 1);
      const MapImage& map = map_of(baked->textures.at(0), Map::normal);
      for (std::size_t texel = 0; texel < 16 * 16; ++texel) {
        ASSERT_NEAR(glm::length(texel3(map, texel) * 2.0 - 1.0 - want), 0, 1e-6) << texel << " scale " << scale << " " << apply;
      }
    }
  }
  // A normal map on a UV set the high-poly lacks is refused, not left out without a word.
  normal.texture.texcoord = 1;
  options.high_normal_maps = true;
  HighMaterials materials;
  materials.normals = {normal};
  auto baked = bake(pair.low, scene_of({high}), {ao::TextureTarget{{0}, 0}}, texture, options, {}, materials);
  ASSERT_FALSE(baked);
  EXPECT_EQ(baked.error().message, "the high-poly's material 0 has a normal map on TEXCOORD_1, which a primitive using it "
                                   "lacks: high_normal_maps cannot apply it (give the primitive that UV set, or the "
                                   "normalTexture the texCoord it has)");
}

// A unit icosphere of 80 triangles placed by `world`, each triangle its own UV island (9 × 9 cells).
constexpr int kCells = 9;
scene::Instance icosphere_low(bool flat, const glm::dmat4& world) {
  const test::AtlasMesh mesh = test::icosphere_atlas(1, flat);
  scene::Instance inst = placed(mesh.positions, mesh.normals, mesh.triangles, world);
  inst.texcoords.push_back(mesh.texcoords);
  return inst;
}

// The runtime's shading normal at barycentric weights w of a low triangle for the decoded texel m,
// in float64 (three.js with vertex tangents): per corner T = normalize(M t), N = normalize(M⁻ᵀ n),
// B = normalize(w_t · cross(N, T)); interpolated, each normalized; normalize(T·m.x + B·m.y + N·m.z).
struct CornerAttributes {
  std::vector<glm::vec4> tangents;  // glTF's TANGENT, object space
  std::vector<glm::vec3> normals;   // object space
};
glm::dmat3 runtime_basis(const scene::Instance& low, const CornerAttributes& corners, std::size_t triangle, const dvec3& w) {
  const auto& [tangents, normals] = corners;
  const glm::dmat3 model(low.world), normal_matrix = glm::transpose(glm::inverse(model));
  dvec3 t(0), b(0), n(0);
  for (int k = 0; k < 3; ++k) {
    const std::size_t c = 3 * triangle + std::size_t(k);
    const dvec3 tc = glm::normalize(model * dvec3(tangents[c])), nc = glm::normalize(normal_matrix * dvec3(normals[c]));
    t += w[k] * tc, n += w[k] * nc;
    b += w[k] * glm::normalize(glm::cross(nc, tc) * double(tangents[c].w));
  }
  return glm::dmat3(glm::normalize(t), glm::normalize(b), glm::normalize(n));
}

double angle(const dvec3& a, const dvec3& b) { return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)); }
double frobenius(const glm::dmat3& m) {
  double s = 0;
  for (int c = 0; c < 3; ++c) s += glm::dot(m[c], m[c]);
  return std::sqrt(s);
}

// The averaged cage's ray directions at the vertices, in float64 (Options::average_normals): the mean
// of the distinct normals of the vertices at each position.
std::vector<dvec3> averaged_directions(const scene::Instance& inst) {
  std::vector<dvec3> out;
  for (const glm::vec3& p : inst.positions) {
    std::vector<dvec3> distinct;
    for (std::size_t u = 0; u < inst.positions.size(); ++u) {
      const dvec3 n(inst.normals[u]);
      const auto same = [&](const dvec3& d) { return glm::dot(d, n) > 1 - 1e-6; };
      if (inst.positions[u] == p && std::none_of(distinct.begin(), distinct.end(), same)) distinct.push_back(n);
    }
    dvec3 sum(0);
    for (const dvec3& d : distinct) sum += d;
    out.push_back(glm::normalize(sum));
  }
  return out;
}

// The high-poly: the unit sphere at `centre` tessellated into 5120 triangles, radial normals. At any
// point q of one of its triangles the interpolated normal is parallel to q − centre (the weights
// that give q from the vertices give Σ w (v − centre) = q − centre): the sphere's own normal there.
// Each low texel's decoded normal must give it back; the hit must lie on the texel's cage ray
// (through the low-poly's point along its interpolated averaged normals: the flat icosphere's split
// vertices meet at each corner) and on the tessellation (between its innermost plane and the sphere).
TEST(Bake, ATessellatedSphereOntoAnIcosphereDecodesToTheSpheresNormalAtEachHit) {
  const dvec3 centre(0.3, -0.2, 0.5);
  const test::Icosphere fine = test::icosphere(4);
  std::vector<dvec3> high_positions, high_normals;
  for (const dvec3& v : fine.vertices) high_positions.push_back(centre + v), high_normals.push_back(v);
  const scene::Scene high = scene_of({placed(high_positions, high_normals, fine.triangles, glm::dmat4(1))});
  double innermost = 1;  // the least distance from the centre to a high triangle's plane
  for (const auto& t : fine.triangles) {
    const dvec3 n = glm::normalize(glm::cross(fine.vertices[t[1]] - fine.vertices[t[0]], fine.vertices[t[2]] - fine.vertices[t[0]]));
    innermost = std::min(innermost, glm::dot(n, fine.vertices[t[0]]));
  }
  const glm::dmat4 rotated = glm::rotate(glm::translate(glm::dmat4(1), centre), 0.7, glm::normalize(dvec3(1, 2, 3)));
  const glm::dmat4 mirrored = glm::scale(rotated, dvec3(-1, 1, 1));
  constexpr int kSide = 9 * 32;
  for (const bool flat : {false, true}) {
    for (const glm::dmat4& world : {rotated, mirrored}) {
      const std::string what = std::string(flat ? "flat" : "smooth") + (world == mirrored ? ", mirrored" : ", rotated");
      const scene::Scene low = scene_of({icosphere_low(flat, world)});
      Options options;
      options.maps = {Map::normal, Map::position};
      options.front = 0.3, options.back = 0.3, options.absolute_distances = true;
      auto baked = bake(low, high, {ao::TextureTarget{{0}, 0}}, {.width = kSide, .height = kSide, .padding = 2}, options);
      ASSERT_TRUE(baked) << baked.error().message;
      const TextureBake& t = baked->textures.at(0);
      EXPECT_EQ(t.misses, 0u) << what;
      const scene::Instance& inst = low.instances[0];
      const std::vector<dvec3> directions = averaged_directions(inst);  // flat: the faces' normals averaged
      const CornerAttributes corners{*corner_tangents(inst, 0), corner_normals(inst)};
      std::size_t checked = 0;
      for (int j = 0; j < kSide; ++j) {
        for (int i = 0; i < kSide; ++i) {
          // The texel centre in its cell, and its weights in the cell's triangle when strictly inside.
          const double cu = (i + 0.5) / kSide * kCells, cv = (j + 0.5) / kSide * kCells;
          const std::size_t k = std::size_t(cv) * kCells + std::size_t(cu);
          const double a = (cu - std::floor(cu) - 0.1) / 0.8, b = (cv - std::floor(cv) - 0.1) / 0.8;
          if (k >= inst.triangles.size() || a <= 1e-9 || b <= 1e-9 || a + b >= 1 - 1e-9) continue;
          const dvec3 w(1 - a - b, a, b);
          const std::size_t texel = std::size_t(j * kSide + i);
          ASSERT_EQ(t.hit[texel], 1) << what;
          dvec3 p(0), n(0);  // the triangle's vertices are 3k, 3k + 1, 3k + 2 in the file's order
          for (int c = 0; c < 3; ++c) {
            p += w[c] * dvec3(inst.positions[3 * k + std::size_t(c)]);
            n += w[c] * directions[3 * k + std::size_t(c)];
          }
          const dvec3 q = texel3(map_of(t, Map::position), texel);
          ASSERT_LT(glm::length(glm::cross(q - p, glm::normalize(n))), 1e-5) << what << ": the hit is off the ray";
          ASSERT_GE(glm::length(q - centre), innermost - 1e-6) << what;
          ASSERT_LE(glm::length(q - centre), 1 + 1e-6) << what;
          const dvec3 sphere_normal = glm::normalize(q - centre);
          // The loader reversed a mirrored node's triangles: corner 1 of the instance is the file's 2.
          const glm::dmat3 basis = runtime_basis(inst, corners, k, world == mirrored ? dvec3(w[0], w[2], w[1]) : w);
          const dvec3 m = texel3(map_of(t, Map::normal), texel) * 2.0 - 1.0;
          // float32 storage and arithmetic: a few ulps of unit vectors.
          ASSERT_LT(angle(glm::normalize(basis * m), sphere_normal), 1e-5) << what << " texel " << i << "," << j;
          // As 8 bits: each component off by Δ (at most half a code, 1/255), the shading moves by at
          // most atan(‖M‖ |Δ| / (1/‖M⁻¹‖ − ‖M‖ |Δ|)), spectral norms bounded by Frobenius ones.
          dvec3 m8;
          for (int c = 0; c < 3; ++c) m8[c] = std::round((m[c] + 1) / 2 * 255) / 255 * 2 - 1;
          const double step = frobenius(basis) * glm::length(m8 - m);
          const double bound = std::atan(step / (glm::length(m) / frobenius(glm::inverse(basis)) - step));
          ASSERT_LE(angle(glm::normalize(basis * m8), sphere_normal), bound + 1e-5) << what;
          ++checked;
        }
      }
      EXPECT_GT(checked, std::size_t(kSide * kSide) / 4) << what;
    }
  }
}

// Curvature: a sphere of radius 2 tessellated into 5120 triangles with radial normals has mean
// curvature 1/2 at every hit (the interpolated normals of a face are (q − centre)/r, whose
// derivative along it is I/r); with its normals turned inward, −1/2 (concave); without normals,
// flat faces, 0. The tolerance: float32 positions and normals, a few ulps of each over the shortest
// edge (the differences the shape operator is solved from), through a 2 × 2 solve.
TEST(Bake, ASpheresCurvatureIsOneOverItsRadiusAtEveryHit) {
  const double radius = 2;
  const dvec3 centre(0.3, -0.2, 0.5);
  const test::Icosphere fine = test::icosphere(4);
  double shortest = radius;
  for (const auto& t : fine.triangles) {
    for (int k = 0; k < 3; ++k) shortest = std::min(shortest, radius * glm::length(fine.vertices[t[k]] - fine.vertices[t[(k + 1) % 3]]));
  }
  const double tolerance = 64 * double(FLT_EPSILON) / shortest;  // relative 64 ε r / shortest, of 1/r
  const glm::dmat4 world = glm::scale(glm::translate(glm::dmat4(1), centre), dvec3(radius));
  const scene::Scene low = scene_of({icosphere_low(false, world)});
  for (const double sign : {1.0, -1.0, 0.0}) {
    std::vector<dvec3> positions, normals;
    for (const dvec3& v : fine.vertices) positions.push_back(centre + radius * v), normals.push_back(sign * v);
    const scene::Scene high = scene_of({placed(positions, sign == 0 ? std::vector<dvec3>{} : normals, fine.triangles, glm::dmat4(1))});
    Options options;
    options.maps = {Map::curvature};
    options.front = 0.3, options.back = 0.3, options.absolute_distances = true;
    auto baked = bake(low, high, {ao::TextureTarget{{0}, 0}}, {.width = 9 * 8, .height = 9 * 8, .texel_samples = 4}, options);
    ASSERT_TRUE(baked) << baked.error().message;
    const TextureBake& t = baked->textures.at(0);
    EXPECT_EQ(t.misses, 0u);
    std::size_t hits = 0;
    for (std::size_t texel = 0; texel < t.hit.size(); ++texel) {
      if (!t.hit[texel]) continue;
      ASSERT_NEAR(map_of(t, Map::curvature).values[texel], sign / radius, tolerance) << "sign " << sign << ", texel " << texel;
      ++hits;
    }
    EXPECT_GT(hits, t.hit.size() / 4);
  }
}

// AO and bent normal at the foot of a wall: the bump test's plane (z = 0 over [-1, 1]²) baked onto
// itself beside a wall at x = 1 facing −x, 10⁴ high and wide. With binary AO and d_max past the
// wall, a ray from the floor is blocked exactly when it heads toward +x, so
//   AO = (1/π) ∫ over x < 0 of cos θ dω = 1/2,   bent ∝ ∫ over x < 0 of ω cos θ dω = (−2/3, 0, π/3).
// AO: a texel's 256 rays (its 4 positions share them) are the first 256 points of a scrambled
// (0, 2)-sequence, one in each strip v ∈ [k/256, (k+1)/256), and a ray heads toward +x exactly
// when v ∈ (3/4, 1) ∪ [0, 1/4): 128 of them, whatever the scramble. Only a ray with 0 < d.x < 2·10⁻⁴
// (over the wall's top at 2 from it) escapes: tolerance one ray, 1/256. Bent normal: each texel's
// estimate is unbiased (a digitally shifted net: each point uniform), the texels' scrambles differ;
// their mean is within 5 standard errors of the closed form (normalizing adds a bias of the
// order of the variance, far below).
TEST(Bake, AoAndBentNormalAtTheFootOfAWallAreTheirClosedForms) {
  BumpPair pair = bump_pair(1, 0.5);  // a 1 × 1 grid: the plane itself
  constexpr double kWall = 1e4;
  const scene::Instance wall = placed({{1, -kWall, 0}, {1, -kWall, kWall}, {1, kWall, kWall}, {1, kWall, 0}},
                                      {}, {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  const scene::Scene high = scene_of({pair.low.instances[0], wall});
  Options options;
  options.maps = {Map::ao, Map::bent_normal};
  options.front = 0.1, options.back = 0.1, options.absolute_distances = true;
  ao::Options occlusion;
  occlusion.samples = 256, occlusion.falloff = ao::Falloff::none, occlusion.absolute_distance = 1e6;
  auto baked = bake(pair.low, high, {ao::TextureTarget{{0}, 0}}, {.width = 32, .height = 32, .texel_samples = 4}, options, occlusion);
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  EXPECT_EQ(t.misses, 0u);
  EXPECT_EQ(t.occlusion_rays, t.texels * 256);
  const dvec3 expected = glm::normalize(dvec3(-2.0 / 3, 0, std::numbers::pi / 3));
  std::vector<dvec3> bent;
  for (std::size_t texel = 0; texel < t.hit.size(); ++texel) {
    ASSERT_EQ(t.hit[texel], 1);
    ASSERT_NEAR(map_of(t, Map::ao).values[texel], 0.5, 1.0 / 256) << texel;
    bent.push_back(texel3(map_of(t, Map::bent_normal), texel) * 2.0 - 1.0);
  }
  dvec3 mean(0);
  for (const dvec3& b : bent) mean += b / double(bent.size());
  double variance = 0;
  for (const dvec3& b : bent) variance += glm::dot(b - mean, b - mean) / double(bent.size() - 1);
  const double standard_error = std::sqrt(variance / double(bent.size()));
  EXPECT_LT(glm::length(mean - expected), 5 * standard_error) << "mean " << mean.x << "," << mean.y << "," << mean.z;
  EXPECT_LT(standard_error, 0.01);  // the test has power: a wrong direction by 0.05 would show
}

// Thickness of a slab: the bump test's plane (z = 0 over [-1, 1]²) onto the top of a slab
// 0.1 thick and 10³ wide (its top facing +z, its bottom −z). A ray into it at angle θ meets the
// bottom (from behind: both faces count) at 0.1 / cos θ, so each ray's depth is 0.1 exactly; only a
// ray with cos θ below 10⁻⁴ leaves by the open sides or passes d_max (a chance of ~10⁻⁸ a ray).
// Tolerance: float32 distances, a few ulps at the coordinates' magnitude (1).
TEST(Bake, ASlabsThicknessIsItsDepthForEveryRay) {
  const BumpPair pair = bump_pair(1, 0.5);
  constexpr double kWide = 1e3, kThick = 0.1;
  const scene::Instance top = placed({{-kWide, -kWide, 0}, {kWide, -kWide, 0}, {kWide, kWide, 0}, {-kWide, kWide, 0}}, {},
                                     {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  const scene::Instance bottom = placed({{-kWide, -kWide, -kThick}, {kWide, -kWide, -kThick}, {kWide, kWide, -kThick}, {-kWide, kWide, -kThick}},
                                        {}, {{0, 2, 1}, {0, 3, 2}}, glm::dmat4(1));
  Options options;
  options.maps = {Map::thickness};
  options.front = 0.05, options.back = 0.05, options.absolute_distances = true;
  ao::Options rays;
  rays.samples = 64;
  auto baked = bake(pair.low, scene_of({top, bottom}), {ao::TextureTarget{{0}, 0}}, {.width = 16, .height = 16, .texel_samples = 4},
                    options, rays);
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  EXPECT_EQ(t.misses, 0u);
  EXPECT_EQ(t.occlusion_rays, t.texels * 64);
  for (std::size_t texel = 0; texel < t.hit.size(); ++texel) {
    ASSERT_EQ(t.hit[texel], 1);
    ASSERT_NEAR(map_of(t, Map::thickness).values[texel], kThick, 1e-5) << texel;
  }
}

// A cage mesh: the plane's quad moved by (0.25, 0, 0.5) onto a high-poly plane 0.1 below it. Each
// ray runs from the cage point towards the low-poly point L and on, so it meets z = −0.1 at
// L + (−0.05, 0, −0.1) (the extrusion's ray, along −z, would meet it at L − (0, 0, 0.1)), and the
// height is −|(−0.05, 0, −0.1)|: inside, along the ray. Tolerance: float32 at magnitude 1.
TEST(Bake, ACageMeshCastsFromItsPointTowardsTheLowPolysPoint) {
  const BumpPair pair = bump_pair(1, 0.5);
  scene::Scene cage = pair.low;
  for (auto& p : cage.instances[0].positions) p += glm::vec3(0.25f, 0.0f, 0.5f);
  const scene::Instance below = placed({{-3, -3, -0.1}, {3, -3, -0.1}, {3, 3, -0.1}, {-3, 3, -0.1}}, {},
                                       {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  Options options;
  options.maps = {Map::height, Map::position};
  options.front = 0.01, options.back = 0.5, options.absolute_distances = true;  // front: where the cage touches
  const ao::TextureOptions texture{.width = 16, .height = 16, .padding = 0, .texel_samples = 1};
  auto baked = bake(pair.low, scene_of({below}), {ao::TextureTarget{{0}, 0}}, texture, options, {}, {}, &cage);
  ASSERT_TRUE(baked) << baked.error().message;
  EXPECT_NEAR(baked->front, std::sqrt(0.25 * 0.25 + 0.5 * 0.5), 1e-6);  // the farthest cage vertex
  const TextureBake& t = baked->textures.at(0);
  EXPECT_EQ(t.misses, 0u);
  for (int j = 0; j < 16; ++j) {
    for (int i = 0; i < 16; ++i) {
      const std::size_t texel = std::size_t(j * 16 + i);
      const dvec3 low(2 * (i + 0.5) / 16 - 1, 1 - 2 * (j + 0.5) / 16, 0);
      ASSERT_NEAR(glm::length(texel3(map_of(t, Map::position), texel) - (low + dvec3(-0.05, 0, -0.1))), 0, 1e-6) << i << "," << j;
      ASSERT_NEAR(map_of(t, Map::height).values[texel], -std::sqrt(0.05 * 0.05 + 0.1 * 0.1), 1e-6) << i << "," << j;
    }
  }
  // Not the low-poly's topology: refused, saying why.
  scene::Scene other = cage;
  other.instances[0].triangles.pop_back();
  EXPECT_NE(cage_mismatch(pair.low, other).find("other vertices or triangles"), std::string::npos);
  auto refused = bake(pair.low, scene_of({below}), {ao::TextureTarget{{0}, 0}}, texture, options, {}, {}, &other);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("the cage"), std::string::npos) << refused.error().message;
}

// Colour transfer: the plane onto itself, the high-poly's copy with UVs turned (u = (y + 1)/2,
// v = (x + 1)/2), COLOR_0 affine over it (blue = (x + 1)/2, exact under interpolation), factor
// (0.5, 1, 1, 0.8) and a 4 × 4 texture ramping red along u and green along v with clamp: sampled
// bilinearly a ramp is clamp((4s − ½)/3, 0, 1) exactly. Each texel (one position, its centre) holds
// factor × texture × COLOR_0 at its own point. Tolerance: float32 weights and texture values.
TEST(Bake, TransferGivesTheHighPolysBaseColourAtEachTexel) {
  const BumpPair pair = bump_pair(1, 0.5);
  scene::Instance high = pair.low.instances[0];
  high.texcoords = {{}};
  for (const auto& p : high.positions) {
    high.texcoords[0].emplace_back((p.y + 1) / 2, (p.x + 1) / 2);
    high.colors.emplace_back(1, 1, (p.x + 1) / 2, 1);
  }
  high.material = 0;
  BaseColor color;
  color.factor = glm::vec4(0.5f, 1, 1, 0.8f);
  MaterialTexture& texture = color.texture.emplace();
  texture.wrap_s = texture.wrap_t = Wrap::clamp_to_edge;
  image::Image& ramp = texture.image;
  ramp.width = ramp.height = 4, ramp.channels = 4;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) ramp.pixels.insert(ramp.pixels.end(), {float(x) / 3, float(y) / 3, 1, 1});
  }
  Options options;
  options.maps = {Map::transfer};
  options.front = 0.05, options.back = 0.05, options.absolute_distances = true;
  constexpr int kSide = 16;
  auto baked = bake(pair.low, scene_of({high}), {ao::TextureTarget{{0}, 0}}, {.width = kSide, .height = kSide, .texel_samples = 1},
                    options, {}, {{color}});
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  const auto ramped = [](double s) { return std::clamp((4 * s - 0.5) / 3, 0.0, 1.0); };
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const double x = 2 * (i + 0.5) / kSide - 1, y = 1 - 2 * (j + 0.5) / kSide;
      const std::size_t texel = std::size_t(j * kSide + i);
      ASSERT_EQ(t.hit[texel], 1);
      const float* v = &map_of(t, Map::transfer).values[4 * texel];
      EXPECT_NEAR(v[0], 0.5 * ramped((y + 1) / 2), 1e-6) << i << "," << j;
      EXPECT_NEAR(v[1], ramped((x + 1) / 2), 1e-6) << i << "," << j;
      EXPECT_NEAR(v[2], (x + 1) / 2, 1e-6) << i << "," << j;
      EXPECT_NEAR(v[3], 0.8, 1e-6) << i << "," << j;
    }
  }
}

// ID: the plane onto a high-poly split at x = 0 into two primitives of materials 0 and 3. A texel
// whose footprint lies on one side holds that material's colour: hue 0 → (0.9, 0.225, 0.225);
// 3 × 0.618034 = 1.854102, hue 0.854102 (sector 5, f = 0.124612) → (0.9, 0.225, 0.815887).
TEST(Bake, IdGivesEachTexelItsHitsMaterialOrPrimitiveColour) {
  const BumpPair pair = bump_pair(1, 0.5);
  const std::vector<dvec3> up(4, dvec3(0, 0, 1));
  scene::Instance left = placed({{-1, -1, 0}, {0, -1, 0}, {0, 1, 0}, {-1, 1, 0}}, up, {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  scene::Instance right = placed({{0, -1, 0}, {1, -1, 0}, {1, 1, 0}, {0, 1, 0}}, up, {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  left.material = 0, right.material = 3;
  Options options;
  options.maps = {Map::id};
  options.front = 0.05, options.back = 0.05, options.absolute_distances = true;
  constexpr int kSide = 16;
  auto baked = bake(pair.low, scene_of({left, right}), {ao::TextureTarget{{0}, 0}}, {.width = kSide, .height = kSide, .texel_samples = 4},
                    options);
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  EXPECT_EQ(t.misses, 0u);
  const dvec3 left_color(0.9, 0.225, 0.225), right_color(0.9, 0.225, 0.815887);
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const dvec3 got = texel3(map_of(t, Map::id), std::size_t(j * kSide + i));
      EXPECT_LT(glm::length(got - (i < kSide / 2 ? left_color : right_color)), 1e-6) << i << "," << j;
    }
  }
  // By primitive: left is mesh 4's primitive 1, right mesh 2's primitive 0, so right is number 0
  // (hue 0) and left number 1 (hue frac(0.618034) × 6 = 3.708204: sector 3, (p, q, v) with
  // q = 0.9 (1 − 0.75 × 0.708204)), whatever their materials.
  left.mesh = 4, left.primitive = 1, right.mesh = 2, right.primitive = 0;
  options.id_by = IdSource::primitive;
  baked = bake(pair.low, scene_of({left, right}), {ao::TextureTarget{{0}, 0}}, {.width = kSide, .height = kSide, .texel_samples = 4},
               options);
  ASSERT_TRUE(baked) << baked.error().message;
  const dvec3 primitive_1(0.225, 0.4219623, 0.9), primitive_0(0.9, 0.225, 0.225);
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const dvec3 got = texel3(map_of(baked->textures.at(0), Map::id), std::size_t(j * kSide + i));
      EXPECT_LT(glm::length(got - (i < kSide / 2 ? primitive_1 : primitive_0)), 1e-6) << i << "," << j;
    }
  }
}

// Per-vertex maps on a sphere: an icosphere of 42 vertices at radius 1.8 (radial normals) inside
// the radius-2 sphere of the curvature test. Every low vertex's direction d is a vertex of the fine
// tessellation too (subdividing keeps them), so its ray, radial (the extrusion's, or from a cage
// vertex at radius 2.4), meets the sphere at centre + 2d: height 0.2 and curvature 1/2 exactly.
// Tolerances: float32 at the coordinates' magnitude (a few ulps of 2.5); curvature as that test's.
TEST(Bake, PerVertexHeightAndCurvatureOfASphereAreItsClosedFormsWithOrWithoutACage) {
  const dvec3 centre(0.3, -0.2, 0.5);
  const test::Icosphere fine = test::icosphere(4), coarse = test::icosphere(1);
  const auto sphere = [&](const test::Icosphere& mesh, double radius) {
    std::vector<dvec3> positions, normals;
    for (const dvec3& v : mesh.vertices) positions.push_back(centre + radius * v), normals.push_back(v);
    return scene_of({placed(positions, normals, mesh.triangles, glm::dmat4(1))});
  };
  const scene::Scene high = sphere(fine, 2), low = sphere(coarse, 1.8), cage = sphere(coarse, 2.4);
  for (const scene::Scene* with : {static_cast<const scene::Scene*>(nullptr), &cage}) {
    Options options;
    options.maps = {};
    options.vertex_maps = {Map::height, Map::curvature};
    options.front = 0.5, options.back = 0.5, options.absolute_distances = true;
    auto baked = bake(low, high, {}, {}, options, {}, {}, with);
    ASSERT_TRUE(baked) << baked.error().message;
    const VertexBake& v = baked->vertices;
    EXPECT_TRUE(baked->textures.empty());
    EXPECT_EQ(v.vertices, coarse.vertices.size());
    EXPECT_EQ(v.misses, 0u);
    ASSERT_EQ(v.values.size(), 2u);
    for (std::size_t i = 0; i < coarse.vertices.size(); ++i) {
      ASSERT_NEAR(v.values[0][0][i], 0.2, 4e-6) << "vertex " << i << (with ? " (cage)" : "");
      ASSERT_NEAR(v.values[1][0][i], 0.5, 1e-3) << "vertex " << i;
    }
  }
}

// Per-vertex AO and thickness: the bump test's plane's four vertices, (±1, ±1, 0), over the closed
// forms of the texture tests. AO: a floor to x = 1.5 under a wall there, 10⁴ high and wide: a
// vertex's 256 rays, the first 256 points of its (0, 2)-sequence, block exactly the 128 heading
// toward +x (tolerance one ray, 1/256). Thickness: the slab 0.1 thick, every ray's depth 0.1.
TEST(Bake, PerVertexAoAndThicknessAreTheTexelsClosedForms) {
  const BumpPair pair = bump_pair(1, 0.5);
  constexpr double kWide = 1e4, kThick = 0.1;
  const scene::Instance floor = placed({{-3, -kWide, 0}, {1.5, -kWide, 0}, {1.5, kWide, 0}, {-3, kWide, 0}}, {},
                                       {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  const scene::Instance wall = placed({{1.5, -kWide, 0}, {1.5, -kWide, kWide}, {1.5, kWide, kWide}, {1.5, kWide, 0}}, {},
                                      {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  const scene::Instance top = placed({{-kWide, -kWide, 0}, {kWide, -kWide, 0}, {kWide, kWide, 0}, {-kWide, kWide, 0}}, {},
                                     {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  const scene::Instance bottom = placed({{-kWide, -kWide, -kThick}, {kWide, -kWide, -kThick}, {kWide, kWide, -kThick}, {-kWide, kWide, -kThick}},
                                        {}, {{0, 2, 1}, {0, 3, 2}}, glm::dmat4(1));
  Options options;
  options.maps = {};
  options.front = 0.1, options.back = 0.1, options.absolute_distances = true;
  ao::Options occlusion;
  occlusion.samples = 256, occlusion.falloff = ao::Falloff::none, occlusion.absolute_distance = 1e6;
  options.vertex_maps = {Map::ao};
  auto walled = bake(pair.low, scene_of({floor, wall}), {}, {}, options, occlusion);
  ASSERT_TRUE(walled) << walled.error().message;
  EXPECT_EQ(walled->vertices.occlusion_rays, 4u * 256);
  options.vertex_maps = {Map::thickness};
  auto slab = bake(pair.low, scene_of({top, bottom}), {}, {}, options, occlusion);
  ASSERT_TRUE(slab) << slab.error().message;
  for (std::size_t v = 0; v < 4; ++v) {
    EXPECT_NEAR(walled->vertices.values[0][0][v], 0.5, 1.0 / 256) << v;
    EXPECT_NEAR(slab->vertices.values[0][0][v], kThick, 1e-5) << v;
  }
  EXPECT_EQ(walled->vertices.misses + slab->vertices.misses, 0u);
}

// Nothing outside a convex mesh occludes it: AO from its surface is 1 at every texel and vertex,
// exactly. The high-poly is a sphere of 5120 triangles, the low-poly its 80-triangle icosphere turned
// so that no cage ray lands on the high-poly's edges. Radial normals lean from the faces, so some of
// a hit's rays leave below the plane of the face they start on and would meet that face again
// (Cycles skips the face a ray leaves; so must the bake: without it a texel read 63/64).
TEST(Bake, AoOnAConvexHighPolyIsOneAtEveryTexelAndVertex) {
  const test::Icosphere fine = test::icosphere(4);
  const scene::Scene high = scene_of({placed(fine.vertices, fine.vertices, fine.triangles, glm::dmat4(1))});
  const scene::Scene low = scene_of({icosphere_low(false, glm::rotate(glm::dmat4(1), 0.7, glm::normalize(dvec3(1, 2, 3))))});
  Options options;
  options.maps = {Map::ao};
  options.vertex_maps = {Map::ao};
  options.front = 0.3, options.back = 0.3, options.absolute_distances = true;
  ao::Options occlusion;
  occlusion.samples = 64, occlusion.falloff = ao::Falloff::none, occlusion.absolute_distance = 0.5;
  auto baked = bake(low, high, {ao::TextureTarget{{0}, 0}}, {.width = kCells * 16, .height = kCells * 16, .padding = 0}, options,
                    occlusion);
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  ASSERT_GT(t.texels, 0u);
  EXPECT_EQ(t.misses, 0u);
  std::size_t below_one = 0;
  for (float ao : map_of(t, Map::ao).values) below_one += ao != 1.0f;
  EXPECT_EQ(below_one, 0u) << "of " << t.texels << " texels";
  for (float ao : baked->vertices.values[0][0]) EXPECT_EQ(ao, 1.0f);
}

// A vertex whose ray misses: the plane's quad (vertices 0 (−1, −1), 1 (1, −1), 2 (1, 1), 3 (−1, 1);
// triangles 0 1 2 and 0 2 3) over a high-poly only where x < 0.5, the plane z = −0.1 − 0.05 y.
// Vertices 0 and 3 hit it at heights −0.05 and −0.15; 1 and 2 miss and take the mean of their hit
// neighbours: 1 sees only 0 (−0.05), 2 sees 0 and 3 (−0.1).
TEST(Bake, AVertexWhoseRayMissesTakesTheMeanOfItsHitNeighbours) {
  const BumpPair pair = bump_pair(1, 0.5);
  const scene::Instance half = placed({{-3, -3, 0.05}, {0.5, -3, 0.05}, {0.5, 3, -0.25}, {-3, 3, -0.25}}, {},
                                      {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
  Options options;
  options.maps = {};
  options.vertex_maps = {Map::height};
  options.front = 0.5, options.back = 0.5, options.absolute_distances = true;
  auto baked = bake(pair.low, scene_of({half}), {}, {}, options);
  ASSERT_TRUE(baked) << baked.error().message;
  EXPECT_EQ(baked->vertices.misses, 2u);
  const std::vector<float>& height = baked->vertices.values[0][0];
  const double expected[4] = {-0.05, -0.05, -0.1, -0.15};
  for (std::size_t v = 0; v < 4; ++v) EXPECT_NEAR(height[v], expected[v], 1e-6) << v;
  // Only scalar maps a vertex can hold.
  options.vertex_maps = {Map::normal};
  EXPECT_FALSE(bake(pair.low, scene_of({half}), {}, {}, options));
}

}  // namespace
}  // namespace matbake::bake

namespace matbake::bake {
namespace {

// Matching by name: Substance's examples of its rule (a name up to the first suffix, the whole name
// without one, case-sensitive).
TEST(BakeParts, ANamesKeyIsItUpToItsFirstSuffix) {
  EXPECT_EQ(part_key("body_high", "_high"), "body");
  EXPECT_EQ(part_key("body_high_top", "_high"), "body");
  EXPECT_EQ(part_key("body_high_1", "_high"), "body");
  EXPECT_EQ(part_key("Leg_high_high_top", "_high"), "Leg");
  EXPECT_EQ(part_key("body_top_high", "_high"), "body_top");
  EXPECT_EQ(part_key("body-high", "_high"), "body-high");
  EXPECT_EQ(part_key("Leg_low_top", "_low"), "Leg");
  EXPECT_EQ(part_key("", "_low"), "");
  scene::Scene low, high;
  for (const char* name : {"body_low", "Head_low", "Leg_low_top", "Head_low"}) low.instances.push_back({.name = name});
  for (const char* name : {"Leg_high", "body_high", "head_high", "body_high_2"}) high.instances.push_back({.name = name});
  const PartMatch parts = match_parts(low, high);
  EXPECT_EQ(parts.high, (std::vector<std::uint32_t>{0, 1, 2, 1}));
  ASSERT_EQ(parts.low.size(), 4u);
  EXPECT_EQ(parts.low[0], 1u);  // body
  EXPECT_EQ(parts.low[2], 0u);  // Leg
  EXPECT_EQ(parts.low[1], parts.low[3]);
  EXPECT_TRUE(std::find(parts.high.begin(), parts.high.end(), parts.low[1]) == parts.high.end());  // Head meets nothing
  EXPECT_EQ(parts.unmatched, std::vector<std::string>{"Head_low"});
}

// A square quad z = `z` over [x0, x1] × [−2, 2], facing +z (or −z), named.
scene::Instance quad(double z, double x0, double x1, bool up, const char* name) {
  scene::Instance q = placed({{x0, -2, z}, {x1, -2, z}, {x1, 2, z}, {x0, 2, z}}, {}, up ? std::vector<std::array<std::uint32_t, 3>>{{0, 1, 2}, {0, 2, 3}}
                                                                                     : std::vector<std::array<std::uint32_t, 3>>{{0, 2, 1}, {0, 3, 2}},
                             glm::dmat4(1));
  q.name = name;
  return q;
}

// Two high-poly parts over the bump test's plane (named a_low): its own, a_high, 0.02 below it, and
// b_high 0.02 above it where x < 0 (facing up, within the cage's front). Every ray meets b_high
// first where it can; matched by name, a_low's rays meet only a_high: height −0.02 at every texel
// and vertex. Tolerance: float32 at magnitude 1.
TEST(BakeParts, MatchedByNameALowPartsRaysMeetOnlyItsHighPart) {
  BumpPair pair = bump_pair(1, 0.5);
  pair.low.instances[0].name = "a_low";
  const scene::Scene high = scene_of({quad(-0.02, -3, 3, true, "a_high"), quad(0.02, -3, 0, true, "b_high")});
  Options options;
  options.maps = {Map::height};
  options.vertex_maps = {Map::height};
  options.front = 0.05, options.back = 0.05, options.absolute_distances = true;
  const ao::TextureOptions texture{.width = 16, .height = 16, .padding = 0, .texel_samples = 1};
  for (Match match : {Match::always, Match::by_name}) {
    options.match = match;
    auto baked = bake(pair.low, high, {ao::TextureTarget{{0}, 0}}, texture, options);
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_TRUE(baked->unmatched.empty());
    const TextureBake& t = baked->textures.at(0);
    EXPECT_EQ(t.misses, 0u);
    for (int j = 0; j < 16; ++j) {
      for (int i = 0; i < 16; ++i) {
        const bool under_b = i < 8 && match == Match::always;
        ASSERT_NEAR(map_of(t, Map::height).values[std::size_t(j * 16 + i)], under_b ? 0.02 : -0.02, 1e-6) << i << "," << j;
      }
    }
    const std::vector<float>& vertex = baked->vertices.values[0][0];  // vertices 0 and 3 at x = −1
    for (std::size_t v = 0; v < 4; ++v) EXPECT_NEAR(vertex[v], (v == 0 || v == 3) && match == Match::always ? 0.02 : -0.02, 1e-6) << v;
  }
  // A low part no high part matches: every ray misses, and the bake names it.
  pair.low.instances[0].name = "c_low";
  options.match = Match::by_name;
  auto unmatched = bake(pair.low, high, {ao::TextureTarget{{0}, 0}}, texture, options);
  ASSERT_TRUE(unmatched) << unmatched.error().message;
  EXPECT_EQ(unmatched->unmatched, std::vector<std::string>{"c_low"});
  EXPECT_EQ(unmatched->textures.at(0).missed_texels, unmatched->textures.at(0).texels);
  EXPECT_EQ(unmatched->vertices.misses, 4u);
}

// AO under a ceiling of another part: a_high (the plane, 0.02 below a_low) under b_high, a quad 0.1
// above it facing down, 10⁴ wide. Matched, with the matched occluders, a_high alone is open: AO
// exactly 1. With every part occluding, the rays are those of the bake without matching, texel for
// texel; for the infinite ceiling at h = 0.1 over binary rays reaching d = 0.2, the cosine-weighted
// chance of missing it is (h/d)² = 1/4 (a ray meets it within d where cos θ ≥ h/d). Tolerance: 64
// rays a texel averaged over 256 texels, a standard error of about 0.004; 0.02 is five of them.
TEST(BakeParts, MatchedOccludersLeaveOutTheOtherPartsAndAllKeepsThem) {
  BumpPair pair = bump_pair(1, 0.5);
  pair.low.instances[0].name = "a_low";
  const scene::Scene high = scene_of({quad(-0.02, -3, 3, true, "a_high"), quad(0.08, -1e4, 1e4, false, "b_high")});
  Options options;
  options.maps = {Map::ao};
  options.front = 0.05, options.back = 0.05, options.absolute_distances = true;
  ao::Options occlusion;
  occlusion.samples = 64, occlusion.falloff = ao::Falloff::none, occlusion.absolute_distance = 0.2;
  const ao::TextureOptions texture{.width = 16, .height = 16, .padding = 0, .texel_samples = 1};
  const auto ao_of = [&](Match match, Occluders occluders) {
    options.match = match, options.occluders = occluders;
    auto baked = bake(pair.low, high, {ao::TextureTarget{{0}, 0}}, texture, options, occlusion);
    EXPECT_TRUE(baked);
    EXPECT_EQ(baked->textures.at(0).misses, 0u);
    return map_of(baked->textures.at(0), Map::ao).values;
  };
  const std::vector<float> always = ao_of(Match::always, Occluders::matched);
  const std::vector<float> matched = ao_of(Match::by_name, Occluders::matched);
  const std::vector<float> all = ao_of(Match::by_name, Occluders::all);
  EXPECT_EQ(all, always);
  double mean = 0;
  for (std::size_t texel = 0; texel < matched.size(); ++texel) {
    EXPECT_EQ(matched[texel], 1.0f) << texel;
    mean += always[texel] / double(always.size());
  }
  EXPECT_NEAR(mean, 0.25, 0.02);
}

}  // namespace
}  // namespace matbake::bake

namespace matbake::bake {
namespace {

// The box [−s, s]³ with split normals, as a hard-edged low-poly is stored: 24 vertices, each face
// its own four with the face's normal.
scene::Instance hard_box(double s, const glm::dmat4& world = glm::dmat4(1)) {
  std::vector<dvec3> positions, normals;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      dvec3 n(0), u(0), v(0);
      n[axis] = sign, u[(axis + 1) % 3] = 1, v[(axis + 2) % 3] = sign;  // u × v = n: counter-clockwise seen from outside
      const auto first = std::uint32_t(positions.size());
      for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        positions.push_back(s * (n + double(a) * u + double(b) * v));
        normals.push_back(n);
      }
      triangles.push_back({first, first + 1, first + 2});
      triangles.push_back({first, first + 2, first + 3});
    }
  }
  return placed(positions, normals, triangles, world);
}

// A hard-edged box (split normals) under the same box 1.1 times larger, per vertex. Extruded along
// its own normal, the three vertices at a corner c cast three rays (from c + f·n, along −n) that
// meet the large box's three faces at height 0.1 each, at three points. With averaged normals they
// are one ray, from c + f·c/|c| along the diagonal, meeting the large box's corner 1.1·c: height
// |1.1·c − c| = 0.1·√3, position 1.1·c, the same for all three. Where the low-poly has no split
// normals (the bump test's plane), the averaged cage's rays are the extrusion's (their origins and
// the height's arithmetic differ by rounding). Tolerance: float32 at magnitude 1.
TEST(Bake, AveragedNormalsCastOneRayWhereAHardEdgesSplitVerticesMeet) {
  const scene::Scene low = scene_of({hard_box(1.0)});
  const scene::Scene high = scene_of({hard_box(1.1)});
  Options options;
  options.maps = {};
  options.vertex_maps = {Map::height};
  options.front = 0.3, options.back = 0.3, options.absolute_distances = true;
  for (const bool averaged : {false, true}) {
    options.average_normals = averaged;
    auto baked = bake(low, high, {}, {}, options);
    ASSERT_TRUE(baked) << baked.error().message;
    EXPECT_EQ(baked->vertices.misses, 0u);
    EXPECT_NEAR(baked->front, 0.3, 1e-6);
    for (float h : baked->vertices.values[0][0]) EXPECT_NEAR(h, averaged ? 0.1 * std::sqrt(3.0) : 0.1, 1e-6) << averaged;
  }
  BumpPair pair = bump_pair(8, 0.5);
  options.maps = {Map::normal, Map::height};
  const ao::TextureOptions texture{.width = 16, .height = 16, .texel_samples = 4};
  options.average_normals = false;
  auto extruded = bake(pair.low, pair.high, {ao::TextureTarget{{0}, 0}}, texture, options);
  options.average_normals = true;
  auto averaged = bake(pair.low, pair.high, {ao::TextureTarget{{0}, 0}}, texture, options);
  ASSERT_TRUE(extruded && averaged);
  for (std::size_t m = 0; m < 2; ++m) {
    const std::vector<float>&a = extruded->textures[0].maps[m].values, &b = averaged->textures[0].maps[m].values;
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-6) << m << " " << i;
  }
}

// The bump of radius 0.5 with the cage's front 0.2 (scene units): a texel's ray starts beneath the
// bump wherever its surface is higher than 0.2, and finds nothing. Those texels, and no others,
// miss (one position a texel: its centre); the probe's reach for them is the bump's height there,
// whose 95th percentile is the front that would have met 95% of them (float64 reference over the
// same texel centres; float32 distances of magnitude 3). The mask is (0, 1, 0) on exactly those
// texels, (1, 0, 0) on the others: neither filled nor padded.
TEST(BakeMisses, ACageBelowABumpMissesWhereTheBumpRisesAboveItAndSaysHowFarToReach) {
  const BumpPair pair = bump_pair(40, 0.5);
  Options options;
  options.maps = {Map::height, Map::mask};
  options.front = 0.2, options.back = 0.25, options.absolute_distances = true;
  const ao::TextureOptions texture{.width = 64, .height = 64, .padding = 2, .texel_samples = 1};
  auto baked = bake(pair.low, pair.high, {ao::TextureTarget{{0}, 0}}, texture, options);
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  std::vector<double> above;
  for (int j = 0; j < 64; ++j) {
    for (int i = 0; i < 64; ++i) {
      const double z = bump_surface(pair, 2 * (i + 0.5) / 64 - 1, 1 - 2 * (j + 0.5) / 64).z;
      ASSERT_GT(std::abs(z - 0.2), 1e-4) << "a texel on the boundary would make the count a coin toss";
      if (z > 0.2) above.push_back(z);
      const dvec3 mask = texel3(map_of(baked->textures[0], Map::mask), std::size_t(j * 64 + i));
      ASSERT_EQ(mask, z > 0.2 ? dvec3(0, 1, 0) : dvec3(1, 0, 0)) << i << "," << j;
    }
  }
  ASSERT_GT(above.size(), 100u);
  EXPECT_EQ(t.samples, 64u * 64u);
  EXPECT_EQ(t.misses, above.size());
  EXPECT_EQ(t.missed_texels, above.size());
  EXPECT_EQ(t.from_inside, 0u);  // an open sheet: the rays beneath it meet nothing at all
  std::sort(above.begin(), above.end());
  EXPECT_NEAR(t.reach_front, above[std::min(above.size() - 1, above.size() * 95 / 100)], 1e-5);
  EXPECT_EQ(t.reach_back, 0);
  const std::string cause = miss_cause(baked->boxes, t, options, 2 * std::sqrt(2.0));
  EXPECT_EQ(cause.rfind("the cage is too small: front 0.", 0), 0u) << cause;
  EXPECT_NE(cause.find("(scene units)"), std::string::npos) << cause;
}

// A closed box floating over a sheet (x, y in [-0.25, 0.25], z in [0.05, 0.3]), the sheet 0.05 below
// the low-poly plane, the cage's front 0.1: the rays of the texels under the box start inside it,
// leave through its bottom (a face's back) and read the sheet: counted, every one of them (16 × 16
// texel centres lie under the box at 64², none on its edges), and no other. Every texel's height is
// the sheet's.
TEST(BakeMisses, RaysThatStartInsideAClosedPartAreCounted) {
  BumpPair pair = bump_pair(1, 0.5);  // the plane; its high-poly replaced
  const glm::dmat4 knob = glm::scale(glm::translate(glm::dmat4(1), dvec3(0, 0, 0.175)), dvec3(0.25, 0.25, 0.125));
  const scene::Scene high = scene_of({quad(-0.05, -3, 3, true, "sheet"), hard_box(1, knob)});
  Options options;
  options.maps = {Map::height};
  options.front = 0.1, options.back = 0.1, options.absolute_distances = true;
  const ao::TextureOptions texture{.width = 64, .height = 64, .padding = 2, .texel_samples = 1};
  auto baked = bake(pair.low, high, {ao::TextureTarget{{0}, 0}}, texture, options);
  ASSERT_TRUE(baked) << baked.error().message;
  const TextureBake& t = baked->textures.at(0);
  EXPECT_EQ(t.from_inside, 16u * 16u);
  EXPECT_EQ(t.misses, 0u);
  for (float h : map_of(t, Map::height).values) ASSERT_NEAR(h, -0.05, 1e-6);
}

// The plane's two halves, each a quad over its own high-poly (x < 0: a sheet 0.05 below; x > 0: one
// 0.05 above). Half A's UVs fill the 0–1 tile; half B's are A's moved one whole tile right (the way
// an artist keeps a mirrored half out of the bake). The 0–1 tile holds A's height alone (−0.05 at
// every texel; wrapped in, B would average it to 0), B's two triangles are counted as outside, and
// no texel is overlapped. With B's UVs moved back into the tile, every texel holds the mean of the
// two (0) and is counted as overlapped.
TEST(BakeTiles, AShellMovedOutByWholeTilesIsNotBakedIntoTheTile) {
  const auto half = [](int mesh, double x0, double x1, double u0) {
    scene::Instance q = placed({{x0, -1, 0}, {x1, -1, 0}, {x1, 1, 0}, {x0, 1, 0}}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
                               {{0, 1, 2}, {0, 2, 3}}, glm::dmat4(1));
    q.texcoords.push_back({{u0, 1}, {u0 + 1, 1}, {u0 + 1, 0}, {u0, 0}});
    q.mesh = mesh;  // two meshes: one mesh placed twice would be one surface
    return q;
  };
  const scene::Scene high = scene_of({quad(-0.05, -3, 0, true, "a"), quad(0.05, 0, 3, true, "b")});
  Options options;
  options.maps = {Map::height};
  options.front = 0.1, options.back = 0.1, options.absolute_distances = true;
  const ao::TextureOptions texture{.width = 32, .height = 32, .padding = 2, .texel_samples = 1};
  for (const double shift : {1.0, 0.0}) {
    const scene::Scene low = scene_of({half(0, -1, 0, 0), half(1, 0, 1, shift)});
    auto baked = bake(low, high, {ao::TextureTarget{{0, 1}, 0}}, texture, options);
    ASSERT_TRUE(baked) << baked.error().message;
    const TextureBake& t = baked->textures.at(0);
    EXPECT_EQ(t.outside_tile, shift == 1 ? 2u : 0u);
    EXPECT_EQ(t.overlapped, shift == 1 ? 0u : 32u * 32u);
    for (float h : map_of(t, Map::height).values) ASSERT_NEAR(h, shift == 1 ? -0.05 : 0.0, 1e-6) << shift;
  }
}

// What the two meshes' boxes say: a high-poly 100× the low-poly (centimetres against metres), one
// moved away, and one in place over a small cage (or wanting so far that a hole is the cause).
TEST(BakeMisses, TheCauseNamedIsUnitsPlacementOrTheCage) {
  const scene::Scene low = scene_of({hard_box(1)});
  const scene::Scene in_cm = scene_of({hard_box(100)});
  const scene::Scene moved = scene_of({hard_box(1, glm::translate(glm::dmat4(1), dvec3(30, 0, 0)))});
  const scene::Scene in_place = scene_of({hard_box(1.2)});
  const Boxes units = compare_boxes(low, in_cm), placement = compare_boxes(low, moved), cage = compare_boxes(low, in_place);
  EXPECT_NEAR(units.high_diagonal / units.low_diagonal, 100, 1e-4);
  EXPECT_NEAR(placement.overlap, 0, 1e-9);
  EXPECT_NEAR(cage.overlap, 1, 1e-9);
  TextureBake t;
  t.reach_front = 0.2 * 2 * std::sqrt(3.0);  // a fifth of the low-poly's diagonal
  Options options;  // fractions of the diagonal
  const double diagonal = units.low_diagonal;
  EXPECT_NE(miss_cause(units, t, options, diagonal).find("100× the low-poly's"), std::string::npos) << miss_cause(units, t, options, diagonal);
  EXPECT_NE(miss_cause(placement, t, options, diagonal).find("barely overlap (0%"), std::string::npos);
  EXPECT_EQ(miss_cause(cage, t, options, diagonal),
            "the cage is too small: front 0.2 (of the diagonal) would reach 95% of the missed rays that have the high-poly along them");
  EXPECT_EQ(miss_cause(cage, TextureBake{}, options, diagonal).rfind("no high-poly surface lies along the missed rays", 0), 0u);
  // Wanting 0.4 of the diagonal is the far side of the model seen through a hole, not a small cage.
  t.reach_front = 0.4 * 2 * std::sqrt(3.0);
  EXPECT_EQ(miss_cause(cage, t, options, diagonal),
            "the high-poly surface along the missed rays lies 0.4 of the low-poly's diagonal away, farther than any cage "
            "reaches: holes in the high-poly (the rays see its far side), parts of the low-poly it does not have, or "
            "high-poly parts standing that far off the low-poly (give them low-poly parts, or their own cage with match "
            "by_name)");
  // A suggestion is rounded up: 0.07071 (front 0.0707 would fall short) is 0.0708.
  t.reach_front = 0.07071 * 2 * std::sqrt(3.0);
  EXPECT_EQ(miss_cause(cage, t, options, diagonal),
            "the cage is too small: front 0.0708 (of the diagonal) would reach 95% of the missed rays that have the high-poly along them");
}

}  // namespace
}  // namespace matbake::bake
