// The high-to-low bake: per texel of the low-poly (ao/texels' coverage), rays from the cage, the
// first hit on the high-poly, every map from it; then misses filled and padding.
#include "matbake/bake.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <set>
#include <tuple>

#include "../ao/texels.hpp"
#include "../image/huge_pages.hpp"
#include "../ao/tracer.hpp"
#include "../gltf/texture_transform.hpp"
#include "frames.hpp"
#include "high_poly.hpp"

namespace matbake::bake {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

constexpr int kMaxTexelSamples = 1024;

// The low-poly at one point: world position and, as the runtime interpolates them, the normal and
// the tangent basis (columns T, B, N, each normalized; not orthogonal in general).
struct LowPoint {
  glm::vec3 position;
  glm::dmat3 basis;
};

LowPoint low_point(const scene::Instance& inst, const std::vector<CornerFrame>& frames, std::size_t triangle,
                   const glm::dvec3& w) {
  const auto& corners = inst.triangles[triangle];
  glm::dvec3 p(0), t(0), b(0), n(0);
  for (std::size_t k = 0; k < 3; ++k) {
    const CornerFrame& f = frames[3 * triangle + k];
    p += w[int(k)] * glm::dvec3(inst.positions[corners[k]]);
    t += w[int(k)] * glm::dvec3(f.tangent);
    b += w[int(k)] * glm::dvec3(f.bitangent);
    n += w[int(k)] * glm::dvec3(f.normal);
  }
  const auto unit = [](const glm::dvec3& v) { return glm::length(v) > 0 ? glm::normalize(v) : v; };
  return {glm::vec3(p), glm::dmat3(unit(t), unit(b), unit(n))};
}

// A point on an edge moved a hair inside. A position past the triangle, clamped onto its edge (a
// seam texel, an anti-aliasing position beyond it), moves before its ray: on a hard edge that the
// high-poly shares (a bake onto itself) the ray would meet the face beside it as often as its own.
// Any point on an edge whose ray misses is cast again from there: at an open edge of the high-poly
// where it meets the low-poly's (a bake onto itself or a simplification keeping the borders) the
// ray misses as often as it hits.
constexpr double kLeast = 1e-5;  // of the triangle's size: float32 resolves 1e-7 of the positions
bool on_edge(const glm::dvec3& w) { return std::min({w.x, w.y, w.z}) < kLeast; }
// Whether `at` lies outside `uv`, whose nearest point has the weights `w` (beyond float64's rounding).
bool outside(const ao::texels::UvTriangle& uv, const glm::dvec2& at, const glm::dvec3& w) {
  return glm::length(w.x * uv.a + w.y * uv.b + w.z * uv.c - at) > 1e-9;
}
glm::dvec3 inside(glm::dvec3 w) {
  w = glm::max(w, glm::dvec3(kLeast));
  return w / (w.x + w.y + w.z);
}

// The texel's (x, y, z) whose shading, normalize(T·x + B·y + N·z), is the world normal h: the basis
// inverted, then scaled to unit length (the texture holds unit vectors). A basis with no inverse
// (the interpolated vectors coplanar) is projected onto instead.
glm::dvec3 tangent_space(const glm::dmat3& basis, const glm::dvec3& h) {
  const double det = glm::determinant(basis);
  const glm::dvec3 m = std::abs(det) > 1e-9 ? glm::inverse(basis) * h : glm::transpose(basis) * h;
  const double length = glm::length(m);
  return length > 0 ? m / length : glm::dvec3(0, 0, 1);
}

// What a texel's hits add up to, for every map.
struct TexelSum {
  glm::dvec3 normal{0}, position{0}, bent{0};
  glm::dvec4 color{0};
  double height = 0, curvature = 0, occlusion = 0, thickness = 0;
  std::uint64_t occlusion_rays = 0, thickness_rays = 0;
  int hits = 0, rays = 0;
  int from_inside = 0;  // rays that hit, whose first surface was a face's back
  int faced_away = 0;   // rays that missed, having met a face's back
  // Of the rays that missed: how far out (front) or in (back) the high-poly lies along them, where
  // it does (the cage's reach that would have met it).
  std::vector<float> wanted_front, wanted_back;
  int id = -1;  // the first hit's material or primitive number (Options::id_by)
};

// What the report keeps of a traced texel.
// What every cage ray and the maps at its hit need, for texels and vertices alike.
struct Rays {
  const scene::Scene& low;
  const HighPoly& high;
  // Per low instance, scene units: how far out the extrusion's rays start (where a cage mesh
  // touches the low-poly too) and how far beyond the low-poly every ray reaches.
  std::vector<float> front, back;
  const scene::Scene* cage;      // the cage mesh (null: extrusion by front)
  bool curvature;                // asked for
  const ao::Tracer* occlusion;   // the high-poly, for ao and bent_normal (null: neither asked)
  bool bent;                     // bent_normal asked for
  const ao::Tracer* thickness;   // the high-poly two-sided, for thickness (null: not asked)
  int occlusion_samples;
  std::uint64_t occlusion_seed;
  const std::vector<BaseColor>* base_colors;  // for transfer (null: not asked)
  // With Options::high_normal_maps: the high-poly's normal maps and its corners' tangent frames
  // (per instance; empty where it has no UV set for them). Null: its vertex normals.
  const std::vector<std::optional<NormalTexture>>* normal_maps;
  const std::vector<std::vector<CornerFrame>>* high_frames;
  const std::vector<int>* primitive_numbers;  // per high instance, for an id map by primitive (null: by material)
  const PartMatch* parts;                     // Match::by_name's parts (null: every ray meets every part)
  bool occluders_matched;                     // with parts: a hit's AO and thickness rays meet its part only
  float probe;                                // how far a missed ray's probe looks either way (0: no probe)
  bool cage_mesh;                             // the cage is the caller's mesh (not the averaged one)
};

// The high-poly parts low instance `instance`'s cage rays meet.
ao::Parts cage_parts(const Rays& c, std::size_t instance) {
  return c.parts ? ao::Parts{&c.parts->high, c.parts->low[instance]} : ao::Parts{};
}

// One texture target's trace.
struct TraceContext {
  const Rays& rays;
  const std::vector<std::vector<CornerFrame>>& frames;  // per low instance (empty: not baked)
  const ao::TextureTarget& target;
  const ao::TextureOptions& texture;
  std::size_t target_index;
};

// A high-poly texture at a hit, bilinear through its UV set and transform, grey spread to RGB (and
// grey-alpha's alpha kept); false where the instance lacks that UV set.
bool sample_at(const MaterialTexture& m, const scene::Instance& inst, const Hit& hit, float (&texel)[4]) {
  if (std::size_t(m.texcoord) >= inst.texcoords.size() || inst.texcoords[std::size_t(m.texcoord)].empty()) return false;
  const auto& corners = inst.triangles[hit.triangle];
  glm::dvec2 uv(0.0);
  for (int k = 0; k < 3; ++k) uv += double(hit.weights[k]) * glm::dvec2(inst.texcoords[std::size_t(m.texcoord)][corners[std::size_t(k)]]);
  if (m.transform) uv = m.transform(uv);
  texel[0] = texel[1] = texel[2] = texel[3] = 1;
  gltf::sample_bilinear(m.image, uv, m.wrap_s, m.wrap_t, texel);
  const int channels = m.image.channels;
  if (channels < 3) texel[3] = channels == 2 ? texel[1] : 1.0f, texel[1] = texel[2] = texel[0];
  return true;
}

// The high-poly's base colour at a hit: COLOR_0 × the material's factor × its texture.
glm::dvec4 base_color(const std::vector<BaseColor>& colors, const scene::Instance& inst, const Hit& hit) {
  const auto& corners = inst.triangles[hit.triangle];
  glm::dvec4 c(1.0);
  if (!inst.colors.empty()) {
    c = glm::dvec4(0.0);
    for (int k = 0; k < 3; ++k) c += double(hit.weights[k]) * glm::dvec4(inst.colors[corners[std::size_t(k)]]);
  }
  if (inst.material < 0 || std::size_t(inst.material) >= colors.size()) return c;
  const BaseColor& m = colors[std::size_t(inst.material)];
  c *= glm::dvec4(m.factor);
  float texel[4];
  if (!m.texture || !sample_at(*m.texture, inst, hit, texel)) return c;
  return c * glm::dvec4(texel[0], texel[1], texel[2], texel[3]);
}

// The high-poly's shading normal at a hit with its material's normal map applied (glTF's decoding,
// in its tangent basis there: the corners' frames interpolated, each normalized); its
// interpolated vertex normal where it has none.
glm::dvec3 detailed_normal(const Rays& c, const Hit& hit) {
  const scene::Instance& inst = c.high.instance(hit);
  const auto& frames = (*c.high_frames)[hit.instance];
  const int m = inst.material;
  if (m < 0 || std::size_t(m) >= c.normal_maps->size() || !(*c.normal_maps)[std::size_t(m)] || frames.empty()) return glm::dvec3(hit.normal);
  const NormalTexture& map = *(*c.normal_maps)[std::size_t(m)];
  float texel[4];
  if (!sample_at(map.texture, inst, hit, texel)) return glm::dvec3(hit.normal);
  const glm::dvec3 n((2.0 * texel[0] - 1) * map.scale, (2.0 * texel[1] - 1) * map.scale, 2.0 * texel[2] - 1);
  glm::dvec3 t(0), b(0), normal(0);
  for (int k = 0; k < 3; ++k) {
    const CornerFrame& f = frames[3 * hit.triangle + std::size_t(k)];
    t += double(hit.weights[k]) * glm::dvec3(f.tangent), b += double(hit.weights[k]) * glm::dvec3(f.bitangent);
    normal += double(hit.weights[k]) * glm::dvec3(f.normal);
  }
  const auto unit = [](const glm::dvec3& v) { return glm::length(v) > 0 ? glm::normalize(v) : v; };
  const glm::dvec3 shaded = unit(t) * n.x + unit(b) * n.y + unit(normal) * n.z;
  return glm::length(shaded) > 0 ? glm::normalize(shaded) : glm::dvec3(hit.normal);
}

// AO and bent normal from a hit, around the high-poly's normal there, and thickness, into it: the
// point's rays j, j + positions, ... of the sequence keyed by `key` (so a texel's positions cast it
// once through); `scale` is the surface's local length (ao::Tracer::origin_offset).
void trace_from_hit(const Rays& c, const Hit& hit, const LowPoint& low, float scale, int j, int positions, std::uint64_t key,
                    TexelSum& sum) {
  thread_local ao::RayPackets rays;  // scratch: a texel's worth of rays, reused
  rays.resize(ao::packets_for(c.occlusion_samples / positions + 1));
  const ao::Face leaving{hit.instance, hit.triangle};
  const ao::Parts parts = c.parts && c.occluders_matched ? ao::Parts{&c.parts->high, c.parts->high[hit.instance]} : ao::Parts{};
  if (c.occlusion) {
    const glm::vec3 origin = hit.position + hit.normal * c.occlusion->origin_offset(hit.position, scale);
    glm::vec3 bent(0);
    sum.occlusion += c.occlusion->sum_over_rays({origin, hit.normal, leaving, parts}, key, j, positions, rays, sum.occlusion_rays,
                                                c.bent ? &bent : nullptr);
    if (c.bent) sum.bent += tangent_space(low.basis, glm::dvec3(bent)) * double(glm::length(bent));
  }
  if (c.thickness) {
    // The origin's offset below the surface is depth too: added back for every ray.
    const float offset = c.thickness->origin_offset(hit.position, scale);
    std::uint64_t inward = 0;
    sum.thickness += c.thickness->sum_of_depths({hit.position - hit.normal * offset, -hit.normal, leaving, parts}, key, j, positions,
                                                rays, inward) +
                     double(inward) * double(offset);
    sum.thickness_rays += inward;
  }
}

// A cage ray's first hit, and how far before the low-poly point it lies (the height: positive outside).
struct CageHit {
  Hit hit;
  double height;
};

// The cage ray at a point of low instance `instance`: from `from_cage` (the cage mesh's point with
// the same weights) towards it, else (no cage mesh, or it touches the low-poly there) from the
// extrusion's front outside along its normal; either reaching back beyond it (the instance's
// distances), meeting the high-poly parts the instance's rays meet. `from_inside`, when given, is
// set to whether the ray's first surface was a face's back.
std::optional<CageHit> cast(const Rays& c, std::size_t instance, const LowPoint& low, const std::optional<glm::dvec3>& from_cage,
                            bool* from_inside = nullptr) {
  const float front = c.front[instance], back = c.back[instance];
  const ao::Parts parts = cage_parts(c, instance);
  if (from_inside) *from_inside = false;
  if (from_cage) {
    const glm::dvec3 to_low = glm::dvec3(low.position) - *from_cage;
    const double distance = glm::length(to_low);
    // Below float32's resolution at the point the direction is noise: the cage touches the low-poly.
    if (distance > 1e-6 * (1 + glm::length(glm::dvec3(low.position)))) {
      auto hit = c.high.first_hit(glm::vec3(*from_cage), glm::vec3(to_low / distance), float(distance) + back, parts, from_inside);
      if (!hit) return std::nullopt;
      return CageHit{*hit, distance - double(hit->distance)};
    }
  }
  const glm::vec3 n(low.basis[2]);
  if (!(glm::length(n) > 0)) return std::nullopt;
  auto hit = c.high.first_hit(low.position + front * n, -n, front + back, parts, from_inside);
  if (!hit) return std::nullopt;
  return CageHit{*hit, double(front) - double(hit->distance)};
}

// A missed ray's probe: from c.probe outside the low-poly point along its normal to c.probe inside,
// the high-poly's first front face gives the cage reach that would have met it, noted in `sum`:
// where it lies outside, the front (the averaged cage's point lies less far out along the normal
// than front: scaled by that; a cage mesh: how much farther out it must lie); inside, the back
// (reached along the ray, at a slant to the normal).
void probe_miss(const Rays& c, std::size_t instance, const LowPoint& low, const std::optional<glm::dvec3>& from_cage, TexelSum& sum) {
  const glm::dvec3 n = low.basis[2];
  if (!(c.probe > 0) || !(glm::length(n) > 0)) return;
  const auto hit = c.high.first_hit(low.position + c.probe * glm::vec3(n), -glm::vec3(n), 2 * c.probe, cage_parts(c, instance));
  if (!hit) return;
  const double height = double(c.probe) - double(hit->distance);  // positive outside
  const double front = c.front[instance], back = c.back[instance];
  double out = front, cosine = 1;  // how far out along n the ray starts; its direction against −n
  if (from_cage) {
    const glm::dvec3 to_low = glm::dvec3(low.position) - *from_cage;
    const double length = glm::length(to_low), along = -glm::dot(to_low, n);
    if (length > 1e-6 * (1 + glm::length(glm::dvec3(low.position))) && along > 0) out = along, cosine = along / length;
  }
  if (height > out) sum.wanted_front.push_back(float(c.cage_mesh ? height - out : front * height / out));
  if (-height > back * cosine) sum.wanted_back.push_back(float(-height / cosine));
}

// The cage mesh's point of low instance `instance`'s triangle at weights `w` (none without a cage).
std::optional<glm::dvec3> cage_point(const Rays& c, std::size_t instance, std::size_t triangle, const glm::dvec3& w) {
  if (!c.cage) return std::nullopt;
  const auto& corners = c.low.instances[instance].triangles[triangle];
  const auto& cage = c.cage->instances[instance].positions;
  return w.x * glm::dvec3(cage[corners[0]]) + w.y * glm::dvec3(cage[corners[1]]) + w.z * glm::dvec3(cage[corners[2]]);
}

// A cage hit into the sums of the maps: the first hit's id, and all that the hit itself gives.
void add_hit(const Rays& c, const CageHit& cage_hit, const LowPoint& low, TexelSum& sum) {
  const Hit& hit = cage_hit.hit;
  if (sum.hits == 0) sum.id = c.primitive_numbers ? (*c.primitive_numbers)[hit.instance] : c.high.instance(hit).material;
  ++sum.hits;
  sum.normal += tangent_space(low.basis, c.normal_maps ? detailed_normal(c, hit) : glm::dvec3(hit.normal));
  sum.position += glm::dvec3(hit.position);
  sum.height += cage_hit.height;
  if (c.curvature) sum.curvature += c.high.mean_curvature(hit);
  if (c.base_colors) sum.color += base_color(*c.base_colors, c.high.instance(hit), hit);
}

// The texel positions of one surface point (K = texel_samples, stratified over the footprint by the
// (0, 2)-sequence as the AO bake's, each clamped to the triangle), one ray each.
void trace_point(const TraceContext& t, const ao::texels::SurfacePoint& point, std::uint64_t key, TexelSum& sum) {
  const Rays& c = t.rays;
  const scene::Instance& inst = c.low.instances[point.instance];
  const ao::texels::UvTriangle uv =
      ao::texels::uv_triangle(inst, t.target, point.triangle, t.texture.width, t.texture.height);
  const int positions = t.texture.texel_samples;
  float texel_size = 0;
  if (c.occlusion || c.thickness) {
    const auto& tri = inst.triangles[point.triangle];
    texel_size = ao::texels::texel_size(
        double(glm::length(glm::cross(inst.positions[tri[1]] - inst.positions[tri[0]], inst.positions[tri[2]] - inst.positions[tri[0]]))), uv);
  }
  const std::uint64_t occlusion_key = ao::sample_key(c.occlusion_seed, t.target_index, point.texel);
  // A seam texel: its centre (integer coordinates) outside the triangle, its point the nearest on it.
  const glm::dvec2 centre(double(point.texel % std::uint32_t(t.texture.width)), double(point.texel / std::uint32_t(t.texture.width)));
  const bool touched = outside(uv, centre, ao::texels::nearest_weights(uv, centre));
  for (int j = 0; j < positions; ++j) {
    glm::dvec2 at(point.x, point.y);
    if (positions > 1) {
      const ao::Sample2 offset = ao::sample(ao::Sampler::sobol, std::uint32_t(j), ~key);
      at += glm::dvec2(offset.u - 0.5, offset.v - 0.5);
    }
    glm::dvec3 w = ao::texels::nearest_weights(uv, at);
    if (on_edge(w) && (touched || outside(uv, at, w))) w = inside(w);
    LowPoint low = low_point(inst, t.frames[point.instance], point.triangle, w);
    ++sum.rays;
    bool from_inside = false;
    std::optional<glm::dvec3> from = cage_point(c, point.instance, point.triangle, w);
    auto cage_hit = cast(c, point.instance, low, from, &from_inside);
    if (!cage_hit && on_edge(w)) {
      w = inside(w);
      low = low_point(inst, t.frames[point.instance], point.triangle, w);
      from = cage_point(c, point.instance, point.triangle, w);
      cage_hit = cast(c, point.instance, low, from, &from_inside);
    }
    if (!cage_hit) {
      sum.faced_away += from_inside;  // met only the backs of faces: the high-poly faces away
      probe_miss(c, point.instance, low, from, sum);
      continue;
    }
    sum.from_inside += from_inside;
    add_hit(c, *cage_hit, low, sum);
    if (c.occlusion || c.thickness) trace_from_hit(c, cage_hit->hit, low, texel_size, j, positions, occlusion_key, sum);
  }
}

// A tangent-space direction as a normal map holds it: the sum's direction (+z when it has none),
// green as asked, xyz/2 + ½.
void encode_direction(const glm::dvec3& sum, Green green, float* v) {
  glm::dvec3 m = glm::length(sum) > 0 ? glm::normalize(sum) : glm::dvec3(0, 0, 1);
  if (green == Green::directx) m.y = -m.y;
  for (int k = 0; k < 3; ++k) v[k] = float(std::clamp(m[k] * 0.5 + 0.5, 0.0, 1.0));
}

// A per_vertex map's value from a sum with hits.
float scalar(const TexelSum& sum, Map map) {
  switch (map) {
    case Map::ao: return sum.occlusion_rays ? float(sum.occlusion / double(sum.occlusion_rays)) : 1.0f;
    case Map::height: return float(sum.height / sum.hits);
    case Map::curvature: return float(sum.curvature / sum.hits);
    case Map::thickness: return sum.thickness_rays ? float(sum.thickness / double(sum.thickness_rays)) : 0.0f;
    default: return 0.0f;
  }
}

// The texel's value of each map from its sum (it has hits).
void store(const TexelSum& sum, const Options& options, std::size_t texel, TextureBake& out) {
  for (MapImage& image : out.maps) {
    float* v = &image.values[texel * std::size_t(image.channels)];
    switch (image.map) {
      case Map::normal: encode_direction(sum.normal, options.green, v); break;
      case Map::bent_normal: encode_direction(sum.bent, options.green, v); break;
      case Map::ao:
      case Map::height:
      case Map::curvature:
      case Map::thickness: v[0] = scalar(sum, image.map); break;
      case Map::position:
        for (int k = 0; k < 3; ++k) v[k] = float(sum.position[k] / sum.hits);
        break;
      case Map::transfer:
        for (int k = 0; k < 4; ++k) v[k] = float(sum.color[k] / sum.hits);
        break;
      case Map::id: {
        const glm::vec3 rgb = id_color(sum.id);
        for (int k = 0; k < 3; ++k) v[k] = rgb[k];
        break;
      }
      case Map::mask: break;  // store_mask's, hit or not
    }
  }
}

// The mask's texel (Map::mask), written for every traced texel, whether its rays hit or not.
void store_mask(const TexelSum& sum, std::size_t texel, TextureBake& out) {
  for (MapImage& image : out.maps) {
    if (image.map != Map::mask || sum.rays == 0) continue;
    float* v = &image.values[texel * 3];
    v[0] = float(sum.hits) / float(sum.rays), v[1] = float(sum.rays - sum.hits) / float(sum.rays);
    v[2] = float(sum.from_inside) / float(sum.rays);
  }
}

// What a texel nothing maps holds in channel k: flat normals, no occlusion, white, zero height,
// position and curvature.
float background(Map map, int k) {
  if (map == Map::normal || map == Map::bent_normal) return k == 2 ? 1.0f : 0.5f;
  return map == Map::ao || map == Map::transfer ? 1.0f : 0.0f;
}
void background(MapImage& image) {
  const std::size_t texels = image.values.size() / std::size_t(image.channels);
  for (std::size_t t = 0; t < texels; ++t) {
    for (int k = 0; k < image.channels; ++k) image.values[t * std::size_t(image.channels) + std::size_t(k)] = background(image.map, k);
  }
}

// Texels all of whose rays missed (`missed`) take their nearest hit texel's value (`nearest_hit`,
// however far; none when nothing was hit).
void fill_missed(MapImage& image, const std::vector<std::size_t>& missed, const std::vector<std::int64_t>& nearest_hit) {
  const std::size_t channels = std::size_t(image.channels);
  for (std::size_t i = 0; i < missed.size(); ++i) {
    if (nearest_hit[i] < 0) continue;
    for (std::size_t k = 0; k < channels; ++k) image.values[missed[i] * channels + k] = image.values[std::size_t(nearest_hit[i]) * channels + k];
  }
}

// The local length at a vertex's hit (the origin offset's scale): the smaller of the low-poly's
// mean edge length at the vertex and the high-poly's at the hit (its corners', interpolated), so
// that the offset stays below the features of either (a slab's huge faces, a coarse low-poly).
float hit_scale(const ao::Tracer& tracer, const HighPoly& high, const Hit& hit, float low_edge) {
  const auto& lengths = tracer.mesh(hit.instance).edge_length;
  const auto& corners = high.instance(hit).triangles[hit.triangle];
  float scale = 0;
  for (int k = 0; k < 3; ++k) scale += hit.weights[k] * lengths[corners[std::size_t(k)]];
  return std::min(scale, low_edge);
}

// Low instance `instance`'s missed vertices take the mean of their hit neighbours (sharing a
// triangle), ring by ring outwards; those no ring reaches keep the background.
void fill_missed(const scene::Instance& inst, std::vector<std::uint8_t> hit, std::size_t instance, VertexBake& out) {
  std::vector<std::vector<std::uint32_t>> neighbours(hit.size());
  for (const auto& t : inst.triangles) {
    for (std::size_t a = 0; a < 3; ++a) neighbours[t[a]].push_back(t[(a + 1) % 3]), neighbours[t[(a + 1) % 3]].push_back(t[a]);
  }
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  for (;;) {
    std::vector<std::uint32_t> ring;
    for (std::uint32_t v = 0; v < hit.size(); ++v) {
      if (!hit[v] && std::ranges::any_of(neighbours[v], [&](std::uint32_t u) { return hit[u] != 0; })) ring.push_back(v);
    }
    if (ring.empty()) return;
    for (auto& per_map : out.values) {
      std::vector<float>& values = per_map[instance];
      for (std::uint32_t v : ring) {
        double sum = 0;
        int count = 0;
        for (std::uint32_t u : neighbours[v]) {
          if (hit[u]) sum += values[u], ++count;
        }
        values[v] = float(sum / count);
      }
    }
    for (std::uint32_t v : ring) hit[v] = 1;
  }
}

// A vertex's cage ray, or where it misses, the ray of a point a hair inside each triangle using the
// vertex (in order) until one hits: at an open border of the high-poly that the low-poly shares (a
// bake onto itself, a simplification keeping its borders), a ray through the border's vertex misses
// as often as it hits, as a texel's through its edge does. `low` becomes the point that hit.
std::optional<CageHit> cast_at_vertex(const Rays& c, std::size_t instance, std::uint32_t vertex, const std::vector<scene::Vec3>& normals,
                                      const std::vector<std::uint32_t>& triangles, LowPoint& low) {
  const scene::Instance& inst = c.low.instances[instance];
  low = {inst.positions[vertex], glm::dmat3(glm::dvec3(0), glm::dvec3(0), glm::dvec3(normals[vertex]))};  // no tangents read
  const std::optional<glm::dvec3> from_cage =
      c.cage ? std::optional(glm::dvec3(c.cage->instances[instance].positions[vertex])) : std::nullopt;
  if (auto hit = cast(c, instance, low, from_cage)) return hit;
  for (std::uint32_t t : triangles) {
    const auto& corners = inst.triangles[t];
    glm::dvec3 w(0);
    for (int k = 0; k < 3; ++k) w[k] = corners[std::size_t(k)] == vertex ? 1.0 : 0.0;
    w = inside(w);
    glm::dvec3 p(0), n(0);
    for (int k = 0; k < 3; ++k) p += w[k] * glm::dvec3(inst.positions[corners[std::size_t(k)]]), n += w[k] * glm::dvec3(normals[corners[std::size_t(k)]]);
    low = {glm::vec3(p), glm::dmat3(glm::dvec3(0), glm::dvec3(0), glm::length(n) > 0 ? glm::normalize(n) : n)};
    if (auto hit = cast(c, instance, low, cage_point(c, instance, t, w))) return hit;
  }
  return std::nullopt;
}

// Options::vertex_maps at every vertex of every low instance (VertexBake); `c` holds the tracers
// those maps need and no others.
VertexBake bake_vertices(const Rays& c, const std::vector<Map>& maps) {
  VertexBake out;
  out.maps = maps;
  out.values.assign(maps.size(), std::vector<std::vector<float>>(c.low.instances.size()));
  const ao::Tracer* from_hit = c.occlusion ? c.occlusion : c.thickness;
  for (std::size_t k = 0; k < c.low.instances.size(); ++k) {
    const scene::Instance& inst = c.low.instances[k];
    const std::vector<scene::Vec3> normals = ao::shading_normals(inst);
    const std::vector<float> edges = from_hit ? ao::mean_edge_lengths(inst) : std::vector<float>{};
    const std::size_t n = inst.positions.size();
    std::vector<std::vector<std::uint32_t>> triangles_of(n);
    for (std::uint32_t t = 0; t < inst.triangles.size(); ++t) {
      for (std::uint32_t v : inst.triangles[t]) triangles_of[v].push_back(t);
    }
    for (std::size_t m = 0; m < maps.size(); ++m) out.values[m][k].assign(n, background(maps[m], 0));
    std::vector<std::uint8_t> hit(n, 0);
    std::vector<std::uint64_t> rays(n, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t v = range.begin(); v != range.end(); ++v) {
        LowPoint low;
        const auto cage_hit = cast_at_vertex(c, k, std::uint32_t(v), normals, triangles_of[v], low);
        if (!cage_hit) continue;
        TexelSum sum;
        add_hit(c, *cage_hit, low, sum);
        if (from_hit) {
          trace_from_hit(c, cage_hit->hit, low, hit_scale(*from_hit, c.high, cage_hit->hit, edges[v]), 0, 1,
                         ao::sample_key(c.occlusion_seed, k, v), sum);
        }
        for (std::size_t m = 0; m < maps.size(); ++m) out.values[m][k][v] = scalar(sum, maps[m]);
        hit[v] = 1;
        rays[v] = sum.occlusion_rays + sum.thickness_rays;
      }
    });
    out.vertices += n;
    for (std::size_t v = 0; v < n; ++v) out.misses += hit[v] ? 0 : 1, out.occlusion_rays += rays[v];
    fill_missed(inst, std::move(hit), k, out);
  }
  return out;
}

}  // namespace

bool per_vertex(Map map) { return map == Map::ao || map == Map::thickness || map == Map::curvature || map == Map::height; }

int channels(Map map) {
  if (map == Map::transfer) return 4;
  return map == Map::normal || map == Map::bent_normal || map == Map::position || map == Map::id || map == Map::mask ? 3 : 1;
}

glm::vec3 id_color(int id) {
  if (id < 0) return glm::vec3(0.5f);
  const double hue = std::fmod(id * 0.618034, 1.0) * 6, s = 0.75, v = 0.9;
  const int sector = int(hue) % 6;
  const double f = hue - std::floor(hue), p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  const glm::dvec3 rgb[6] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  return glm::vec3(rgb[sector]);
}

std::vector<int> primitive_numbers(const scene::Scene& scene) {
  std::vector<std::pair<int, int>> pairs;
  for (const scene::Instance& inst : scene.instances) pairs.emplace_back(inst.mesh, inst.primitive);
  std::vector<std::pair<int, int>> ordered = pairs;
  std::sort(ordered.begin(), ordered.end());
  ordered.erase(std::unique(ordered.begin(), ordered.end()), ordered.end());
  std::vector<int> numbers;
  for (const auto& pair : pairs) numbers.push_back(int(std::lower_bound(ordered.begin(), ordered.end(), pair) - ordered.begin()));
  return numbers;
}

Status check(const Options& options) {
  if (options.maps.empty() && options.vertex_maps.empty()) return Error{"", "a bake needs at least one map: " + mention("maps") + " or " + mention("vertex_maps"), true};
  if (!std::ranges::all_of(options.vertex_maps, per_vertex)) return Error{"", mention("vertex_maps") + " are among ao, thickness, curvature and height", true};
  if (!(options.front >= 0) || !(options.back >= 0) || !std::isfinite(options.front) || !std::isfinite(options.back) ||
      options.front + options.back <= 0) {
    return Error{"", "the cage distances must be finite, 0 or more, and not both 0", true};
  }
  for (const auto* by_part : {&options.front_by_part, &options.back_by_part}) {
    if (by_part->empty()) continue;
    const char* name = by_part == &options.front_by_part ? "front_by_part" : "back_by_part";
    if (options.match != Match::by_name) return Error{"", mention(name) + " applies with " + mention("match", "by_name"), true};
    for (const auto& [part, distance] : *by_part) {
      if (part.empty() || !(distance >= 0) || !std::isfinite(distance)) {
        return Error{"", mention(name) + ": each part's distance must be finite and 0 or more", true};
      }
    }
  }
  return success();
}

Status check_depth(const Bake& bake, const CageReach& reach) {
  double deepest = std::max(bake.front, bake.back);
  for (const auto* distances : {&reach.front, &reach.back}) {
    for (double d : *distances) deepest = std::max(deepest, d);
  }
  const double size = std::max(bake.boxes.low_diagonal, bake.boxes.high_diagonal);
  if (deepest <= kDeepestCage * size) return success();
  char text[96];
  std::snprintf(text, sizeof text, "the cage reaches %g scene units, more than %g times the meshes' size (%g)", deepest, kDeepestCage, size);
  return Error{"", std::string(text) + ": a ray that long meets nothing a bake wants and loses float precision; lower " +
                       mention("front") + ", " + mention("back") + " or the parts' distances (or move the cage mesh closer)",
               true};
}

CageReach part_distances(const scene::Scene& low, const Options& options) {
  const double scale = options.absolute_distances ? 1.0 : 2.0 * double(low.radius());
  CageReach out;
  std::set<std::string_view> keys;
  for (const scene::Instance& inst : low.instances) {
    const std::string_view key = part_key(inst.name, "_low");
    keys.insert(key);
    const auto of = [&](const std::map<std::string, double, std::less<>>& by_part, double fallback) {
      const auto found = by_part.find(key);
      return (found == by_part.end() ? fallback : found->second) * scale;
    };
    out.front.push_back(of(options.front_by_part, options.front));
    out.back.push_back(of(options.back_by_part, options.back));
  }
  for (const auto* by_part : {&options.front_by_part, &options.back_by_part}) {
    for (const auto& [part, distance] : *by_part) {
      if (keys.contains(part)) continue;
      std::string known;
      for (std::string_view k : keys) {  // appended: GCC 12 -O3 misreads `"'" + std::string`
        known += known.empty() ? "'" : ", '";
        known += escape_control(k);
        known += '\'';
      }
      out.unknown = mention(by_part == &options.front_by_part ? "front_by_part" : "back_by_part") + " names part '" +
                    escape_control(part) + "', which no low-poly part is called (its parts: " + known + ")";
      return out;
    }
  }
  return out;
}

std::pair<double, double> cage_distances(const scene::Scene& low, const Options& options, const scene::Scene* cage) {
  const double scale = options.absolute_distances ? 1.0 : 2.0 * double(low.radius());
  if (!cage) return {options.front * scale, options.back * scale};
  double farthest = 0;  // where the cage touches the low-poly everywhere, the extrusion's front
  for (std::size_t k = 0; k < low.instances.size() && k < cage->instances.size(); ++k) {
    const auto& from = cage->instances[k].positions;
    const auto& to = low.instances[k].positions;
    for (std::size_t v = 0; v < to.size() && v < from.size(); ++v) farthest = std::max(farthest, double(glm::distance(from[v], to[v])));
  }
  return {farthest > 0 ? farthest : options.front * scale, options.back * scale};
}

std::string cage_mismatch(const scene::Scene& low, const scene::Scene& cage) {
  if (cage.instances.size() != low.instances.size()) {
    return "places " + std::to_string(cage.instances.size()) + " primitives where the low-poly places " +
           std::to_string(low.instances.size()) + ": a cage is the low-poly with its vertices moved";
  }
  for (std::size_t k = 0; k < low.instances.size(); ++k) {
    const scene::Instance &a = low.instances[k], &b = cage.instances[k];
    if (a.positions.size() != b.positions.size() || a.triangles != b.triangles) {
      return "primitive " + std::to_string(k) + " (mesh " + std::to_string(b.mesh) + ", primitive " +
             std::to_string(b.primitive) + ") has other vertices or triangles than the low-poly's: a cage is the "
             "low-poly with its vertices moved";
    }
  }
  return "";
}

namespace {

// The high-poly as the asked maps trace it: one BVH for the cage rays, the estimator's occlusion
// (ao and bent_normal) and its depths (thickness, every face from either side), each estimator only
// where a map needs it; the estimator's own BVH only where its traversal is asked to be fast.
struct Tracers {
  std::unique_ptr<HighPoly> high;
  std::unique_ptr<ao::Tracer> occluder, depths;
};

Result<Tracers> build_tracers(const scene::Scene& high, bool occluding, bool thickness, const ao::Options& occlusion) {
  auto bvh = ao::Bvh::build(high, true);
  if (!bvh) return bvh.error();
  Tracers out;
  out.high = HighPoly::build(high, *bvh);
  const auto estimator = [&](const ao::Options& options) { return ao::Tracer::build(high, options, options.watertight ? *bvh : nullptr); };
  if (occluding) {
    auto made = estimator(occlusion);
    if (!made) return made.error();
    out.occluder = std::move(*made);
  }
  if (thickness) {
    ao::Options two_sided = occlusion;
    two_sided.two_sided = true;
    auto made = estimator(two_sided);
    if (!made) return made.error();
    out.depths = std::move(*made);
  }
  return out;
}

// The tangent frames of every instance a target bakes (none for the others).
Result<std::vector<std::vector<CornerFrame>>> target_frames(const scene::Scene& low, const std::vector<ao::TextureTarget>& targets) {
  std::vector<std::vector<CornerFrame>> frames(low.instances.size());
  for (const ao::TextureTarget& target : targets) {
    for (std::size_t k : target.instances) {
      if (k >= low.instances.size()) return Error{"", "internal: a texture target names an instance that does not exist"};
      const scene::Instance& inst = low.instances[k];
      if (!frames[k].empty() || std::size_t(target.texcoord) >= inst.texcoords.size()) continue;  // without UVs: skipped
      auto made = corner_frames(inst, target.texcoord);
      if (!made) return made.error();
      frames[k] = std::move(*made);
    }
  }
  return frames;
}

// The tangent frames of each high-poly instance whose material has a normal map, through its UV
// set (none for the others). An instance without that set is an error: the map asked for would be
// left out without a word.
Result<std::vector<std::vector<CornerFrame>>> normal_map_frames(const scene::Scene& high,
                                                                 const std::vector<std::optional<NormalTexture>>& normals) {
  std::vector<std::vector<CornerFrame>> frames(high.instances.size());
  for (std::size_t k = 0; k < high.instances.size(); ++k) {
    const scene::Instance& inst = high.instances[k];
    if (inst.material < 0 || std::size_t(inst.material) >= normals.size() || !normals[std::size_t(inst.material)]) continue;
    const int texcoord = normals[std::size_t(inst.material)]->texture.texcoord;
    if (std::size_t(texcoord) >= inst.texcoords.size() || inst.texcoords[std::size_t(texcoord)].empty()) {
      return Error{"", "the high-poly's material " + std::to_string(inst.material) + " has a normal map on TEXCOORD_" +
                           std::to_string(texcoord) + ", which a primitive using it lacks: high_normal_maps cannot apply it "
                           "(give the primitive that UV set, or the normalTexture the texCoord it has)"};
    }
    auto made = corner_frames(inst, texcoord);
    if (!made) return made.error();
    frames[k] = std::move(*made);
  }
  return frames;
}

// The counts of one tile's texels for the report (summed over tiles, in any order).
struct TileTally {
  std::size_t texels = 0, samples = 0, occlusion_rays = 0, misses = 0, missed_texels = 0, from_inside = 0, overlapped = 0;
  std::size_t faced_away = 0;
  double height_min = std::numeric_limits<double>::infinity(), height_max = -std::numeric_limits<double>::infinity();
  std::vector<float> wanted_front, wanted_back;  // TexelSum's, of every texel
  void add(const TileTally& o) {
    texels += o.texels, samples += o.samples, occlusion_rays += o.occlusion_rays, misses += o.misses;
    missed_texels += o.missed_texels, from_inside += o.from_inside, overlapped += o.overlapped, faced_away += o.faced_away;
    height_min = std::min(height_min, o.height_min), height_max = std::max(height_max, o.height_max);
    wanted_front.insert(wanted_front.end(), o.wanted_front.begin(), o.wanted_front.end());
    wanted_back.insert(wanted_back.end(), o.wanted_back.begin(), o.wanted_back.end());
  }
};

// The reach that would have met 95% of the missed rays the probes placed (0: none placed).
double reach_for(std::vector<float>& wanted) {
  if (wanted.empty()) return 0;
  const auto at = wanted.begin() + std::ptrdiff_t(std::min(wanted.size() - 1, wanted.size() * 95 / 100));
  std::nth_element(wanted.begin(), at, wanted.end());
  return double(*at);
}

// Whether a texel's points lie on several triangles of the low-poly's meshes (overlapping islands);
// one triangle placed by several nodes is one.
bool overlapping(const scene::Scene& low, const ao::texels::SurfacePoint* first, const ao::texels::SurfacePoint* last) {
  const auto triangle = [&](const ao::texels::SurfacePoint& p) {
    const scene::Instance& inst = low.instances[p.instance];
    return std::tuple(inst.mesh, inst.primitive, p.triangle);
  };
  for (const auto* p = first + 1; p < last; ++p) {
    if (triangle(*p) != triangle(*first)) return true;
  }
  return false;
}

// One tile's texels traced into `out`'s maps: each texel's points into one sum; marks `traced` and
// out.hit (bytes: tiles write their own texels in parallel).
void trace_tile(const TraceContext& context, const Options& options, const ao::texels::TilePoints& tile,
                TextureBake& out, std::vector<std::uint8_t>& traced, TileTally& tally) {
  const auto& points = tile.points;
  for (std::size_t first = 0, last = 0; first < points.size(); first = last) {
    const std::uint32_t texel = points[first].texel;
    TexelSum sum;
    for (last = first; last < points.size() && points[last].texel == texel; ++last) {
      const std::uint64_t key = ao::sample_key(options.seed, context.target_index, texel) ^ (std::uint64_t(last - first) << 32);
      trace_point(context, points[last], key, sum);
    }
    ++tally.texels;
    tally.overlapped += overlapping(context.rays.low, points.data() + first, points.data() + last);
    traced[texel] = 1;
    tally.samples += std::size_t(sum.rays);
    tally.occlusion_rays += sum.occlusion_rays + sum.thickness_rays;
    tally.misses += std::size_t(sum.rays - sum.hits);
    tally.from_inside += std::size_t(sum.from_inside), tally.faced_away += std::size_t(sum.faced_away);
    tally.wanted_front.insert(tally.wanted_front.end(), sum.wanted_front.begin(), sum.wanted_front.end());
    tally.wanted_back.insert(tally.wanted_back.end(), sum.wanted_back.begin(), sum.wanted_back.end());
    store_mask(sum, texel, out);
    if (sum.hits == 0) {
      ++tally.missed_texels;
      continue;
    }
    store(sum, options, texel, out);
    out.hit[texel] = 1;
    const double height = sum.height / sum.hits;
    tally.height_min = std::min(tally.height_min, height), tally.height_max = std::max(tally.height_max, height);
  }
}

// The target's triangles whose UVs lie wholly outside its tile, or are not finite (none of their
// texels baked).
std::size_t triangles_outside_tile(const scene::Scene& low, const ao::TextureTarget& target) {
  std::size_t outside = 0;
  const glm::dvec2 tile(target.tile_origin);
  for (std::size_t k : target.instances) {
    const scene::Instance& inst = low.instances[k];
    if (std::size_t(target.texcoord) >= inst.texcoords.size()) continue;
    const auto& uv = inst.texcoords[std::size_t(target.texcoord)];
    for (const auto& corners : inst.triangles) {
      glm::dvec2 lo(uv[corners[0]]), hi = lo;
      for (std::uint32_t v : corners) lo = glm::min(lo, glm::dvec2(uv[v])), hi = glm::max(hi, glm::dvec2(uv[v]));
      outside += !(hi.x > tile.x && hi.y > tile.y && lo.x < tile.x + 1 && lo.y < tile.y + 1);  // not finite: outside too
    }
  }
  return outside;
}

// Options::maps over one texture target: its texels traced tile by tile as each tile's coverage is
// found (no list of every texel's points), misses filled, padded.
Result<TextureBake> trace_target(const TraceContext& context, const Options& options) {
  const ao::TextureOptions& texture = context.texture;
  const ao::texels::Tiling tiling = ao::texels::tile(context.rays.low, context.target, texture.width, texture.height);
  TextureBake out;
  const std::size_t texel_count = std::size_t(texture.width) * std::size_t(texture.height);
  out.width = texture.width, out.height = texture.height;
  for (Map map : options.maps) {
    MapImage& image = out.maps.emplace_back();
    image.map = map, image.channels = channels(map);
    image::reserve_advised(image.values, texel_count * std::size_t(image.channels));  // a fault per 2 MiB, not per 4 KiB
    image.values.resize(texel_count * std::size_t(image.channels));
    background(image);
  }
  out.hit.assign(texel_count, 0);
  std::vector<std::uint8_t> traced(texel_count, 0);
  std::vector<TileTally> tallies(tiling.fragments.size());
  const Status covered = ao::texels::cover_tiles(context.rays.low, context.target, tiling, ao::texels::kMaxSurfacePoints,
                                                  [&](std::size_t t, const ao::texels::TilePoints& tile) {
                                                    trace_tile(context, options, tile, out, traced, tallies[t]);
                                                  });
  if (!covered) {
    return Error{"", (context.target.name.empty() ? "texture " + std::to_string(context.target_index) : context.target.name) +
                         ": " + covered.error().message};
  }
  TileTally total;
  for (const TileTally& t : tallies) total.add(t);
  out.texels = total.texels, out.samples = total.samples, out.occlusion_rays = total.occlusion_rays;
  out.misses = total.misses, out.missed_texels = total.missed_texels;
  out.from_inside = total.from_inside, out.overlapped = total.overlapped, out.faced_away = total.faced_away;
  out.degenerate_uv = tiling.degenerate_uv, out.too_large = tiling.too_large;
  out.outside_tile = triangles_outside_tile(context.rays.low, context.target);
  out.reach_front = reach_for(total.wanted_front), out.reach_back = reach_for(total.wanted_back);
  if (total.height_min <= total.height_max) out.height_min = total.height_min, out.height_max = total.height_max;
  const std::vector<bool> hit(out.hit.begin(), out.hit.end()), was_traced(traced.begin(), traced.end());
  std::vector<std::size_t> missed;  // traced texels that missed every ray
  for (std::size_t t = 0; out.missed_texels && t < texel_count; ++t) {
    if (traced[t] && !out.hit[t]) missed.push_back(t);
  }
  const std::vector<std::int64_t> nearest_hit = ao::texels::nearest_mapped_to(hit, texture.width, texture.height, missed);
  for (MapImage& image : out.maps) {
    if (image.map == Map::mask) continue;  // the misses as they are
    fill_missed(image, missed, nearest_hit);
    out.padded = ao::texels::pad_channels(image.values, image.channels, was_traced, texture.width, texture.height,
                                          ao::padding_for(texture));
  }
  return out;
}

}  // namespace

Result<Bake> bake(const scene::Scene& low, const scene::Scene& high, const std::vector<ao::TextureTarget>& targets,
                  const ao::TextureOptions& texture, const Options& options, const ao::Options& occlusion,
                  const HighMaterials& materials, const scene::Scene* cage) {
  if (Status s = check(options); !s) return s.error();
  if (cage) {
    if (const std::string why = cage_mismatch(low, *cage); !why.empty()) return Error{"", "the cage " + why, true};
  }
  if (Status s = ao::check(texture, kMaxTexelSamples, "bake"); !s) return s.error();
  const auto in = [](const std::vector<Map>& maps, Map map) { return std::ranges::find(maps, map) != maps.end(); };
  const auto asked = [&](Map map) { return in(options.maps, map); };
  const auto asked_per_vertex = [&](Map map) { return in(options.vertex_maps, map); };
  const bool occluding = asked(Map::ao) || asked(Map::bent_normal) || asked_per_vertex(Map::ao);
  const bool thickness = asked(Map::thickness) || asked_per_vertex(Map::thickness);
  if (occluding || thickness) {
    if (Status s = ao::check(occlusion); !s) return s.error();
  }
  const auto start = Clock::now();
  auto frames = target_frames(low, options.maps.empty() ? std::vector<ao::TextureTarget>{} : targets);
  if (!frames) return frames.error();
  auto tracers = build_tracers(high, occluding, thickness, occlusion);
  if (!tracers) return tracers.error();
  const CageReach reach = part_distances(low, options);
  if (!reach.unknown.empty()) return Error{"", reach.unknown, true};
  if (cage && !options.front_by_part.empty()) {
    return Error{"", mention("front_by_part") + ": the cage mesh sets how far out each part's rays start (give " +
                         mention("back_by_part") + " alone)", true};
  }
  Bake result;
  result.boxes = compare_boxes(low, high);
  std::tie(result.front, result.back) = cage_distances(low, options, cage);  // an averaged cage's: front
  if (Status s = check_depth(result, reach); !s) return s.error();
  const bool cage_mesh = cage != nullptr;
  std::optional<scene::Scene> averaged;
  if (options.average_normals && !cage) {
    averaged = averaged_normal_cage(low, reach.front);
    cage = &*averaged;
  }
  const auto floats = [](const std::vector<double>& v) { return std::vector<float>(v.begin(), v.end()); };
  result.setup_seconds = seconds_since(start);

  const std::vector<int> primitives = primitive_numbers(high);
  // The high-poly's tangent frames, for its normal maps (each instance through its material's UV set).
  const bool detail = options.high_normal_maps && asked(Map::normal) && !materials.normals.empty();
  std::optional<std::vector<std::vector<CornerFrame>>> high_frames;
  if (detail) {
    auto frames_made = normal_map_frames(high, materials.normals);
    if (!frames_made) return frames_made.error();
    high_frames = std::move(*frames_made);
  }
  const std::optional<PartMatch> parts = options.match == Match::by_name ? std::optional(match_parts(low, high)) : std::nullopt;
  if (parts) result.unmatched = parts->unmatched;
  const bool occluders_matched = options.occluders == Occluders::matched;
  const auto trace_start = Clock::now();
  // Each pass's rays read only the tracers and inputs its maps need.
  const Rays texel_rays{low,
                        *tracers->high,
                        floats(reach.front),  // the extrusion's, where a cage mesh touches
                        floats(reach.back),
                        cage,
                        asked(Map::curvature),
                        asked(Map::ao) || asked(Map::bent_normal) ? tracers->occluder.get() : nullptr,
                        asked(Map::bent_normal),
                        asked(Map::thickness) ? tracers->depths.get() : nullptr,
                        occlusion.samples,
                        occlusion.seed,
                        asked(Map::transfer) ? &materials.base_colors : nullptr,
                        detail ? &materials.normals : nullptr,
                        detail ? &*high_frames : nullptr,
                        options.id_by == IdSource::primitive ? &primitives : nullptr,
                        parts ? &*parts : nullptr,
                        occluders_matched,
                        2 * low.radius(),
                        cage_mesh};
  for (std::size_t index = 0; index < targets.size() && !options.maps.empty(); ++index) {
    // The target's tile alone (the 0–1 tile unless a UDIM tile's), as Substance, Marmoset and
    // Blender bake: a shell moved out by whole tiles (a mirrored half kept out of the bake) is not
    // wrapped back into it.
    ao::TextureTarget in_tile = targets[index];
    in_tile.tile_only = true;
    auto traced = trace_target(TraceContext{texel_rays, *frames, in_tile, texture, index}, options);
    if (!traced) return traced.error();
    result.textures.push_back(std::move(*traced));
  }
  if (!options.vertex_maps.empty()) {
    const Rays vertex_rays{low,
                           *tracers->high,
                           texel_rays.front,
                           texel_rays.back,
                           cage,
                           asked_per_vertex(Map::curvature),
                           asked_per_vertex(Map::ao) ? tracers->occluder.get() : nullptr,
                           false,
                           asked_per_vertex(Map::thickness) ? tracers->depths.get() : nullptr,
                           occlusion.samples,
                           occlusion.seed,
                           nullptr,
                           nullptr,
                           nullptr,
                           nullptr,
                           parts ? &*parts : nullptr,
                           occluders_matched,
                           0,
                           cage_mesh};
    result.vertices = bake_vertices(vertex_rays, options.vertex_maps);
  }
  result.trace_seconds = seconds_since(trace_start);
  return result;
}

}  // namespace matbake::bake
