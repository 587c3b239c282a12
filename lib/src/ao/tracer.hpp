#pragma once
// The estimator shared by the per-vertex and the texture bake: a scene in Embree, each vertex's ray
// normal and bias scale, and the mean of μ over cosine-weighted rays from one point.
#include <embree3/rtcore.h>

#include <memory>
#include <span>
#include <vector>

#include "bvh.hpp"
#include "matbake/ao.hpp"

namespace matbake::ao {

struct Mesh {
  std::vector<scene::Vec3> normals;  // per vertex, unit
  std::vector<float> edge_length;    // per vertex: mean length of its edges (the bias scale)
};

// The instance's unit normals: the file's, area-weighted from the faces where it has none (or when
// asked: from the faces with that weighting).
std::vector<scene::Vec3> shading_normals(const scene::Instance& inst, std::optional<scene::NormalWeighting> recompute = {});

// Per vertex, the mean length of its edges (0 for a vertex no triangle uses).
std::vector<float> mean_edge_lengths(const scene::Instance& inst);

// Scratch for one point's rays, 16 to a packet: Embree traverses a packet's rays together, which
// measured a fifth faster than a stream of single rays on closed meshes, where a point's rays share
// the nodes around it and most cross the whole distance (docs/bake.md), and the same elsewhere.
using RayPackets = std::vector<RTCRayHit16>;
inline std::size_t packets_for(int rays) { return std::size_t(rays + 15) / 16; }

// Where a point's rays start: at `origin`, around the unit `normal`, leaving the face `leaving` (never
// a hit; none for a vertex, which no single face holds), meeting only the instances of `parts`.
struct RayStart {
  scene::Vec3 origin, normal;
  Face leaving;
  Parts parts;
};

class Tracer {
 public:
  // Every instance occludes, whatever options.targets says. `bvh`: the scene's, already built (a
  // bake's high-poly, shared with its cage rays), or none to build one (robust unless
  // options.watertight is false). Errors: Embree failing to start or build.
  static Result<std::unique_ptr<Tracer>> build(const scene::Scene& scene, const Options& options,
                                               std::shared_ptr<const Bvh> bvh = nullptr);

  const Mesh& mesh(std::size_t instance) const { return meshes_[instance]; }
  const std::vector<scene::Vec3>& face_normals(std::size_t instance) const { return bvh_->face_normals(instance); }
  double max_distance() const { return d_max_; }

  // The ray-origin offset along the normal at p, for a surface whose local length scale is `scale`
  // (a vertex's mean edge length, a texel's world size): bias × scale, capped at 1e-4 of the scene
  // radius (a huge triangle must not lift the origin through nearby geometry) and at least 1e-6 of
  // p's coordinates' magnitude (float precision there: below it a ray can hit the surface it leaves).
  // Not of the scene's size: a 1e-4 mesh in a 1e4 scene would have its rays start outside it.
  float origin_offset(const scene::Vec3& p, float scale) const;

  // Σ μ over rays first, first + step, ... (below options.samples) of the sequence keyed by `key`,
  // cast from `from`; `rays` is scratch for at least those rays.
  // Returns the sum and adds the ray count to `cast`; with `bent`, adds Σ μ · direction to it (the
  // bent normal's estimator: the mean open direction, cosine-weighted).
  double sum_over_rays(const RayStart& from, std::uint64_t key, int first, int step, std::span<RTCRayHit16> rays,
                       std::uint64_t& cast, scene::Vec3* bent = nullptr) const;

  // Over the same rays: Σ of the depth each reaches along the normal, its distance to the first
  // surface (d_max where it finds none) times the cosine to the normal (for thickness, cast into a surface).
  double sum_of_depths(const RayStart& from, std::uint64_t key, int first, int step, std::span<RTCRayHit16> rays,
                       std::uint64_t& cast) const;

 private:
  Tracer() = default;
  // Fills rays with those of the sequence (first, first + step, ...): cosine-weighted around the
  // unit n from `origin`, out to d_max; returns how many.
  unsigned aim(const scene::Vec3& origin, const scene::Vec3& n, std::uint64_t key, int first, int step,
               std::span<RTCRayHit16> rays) const;
  // The first `count` rays traced, for their first hit or (`occlusion_only`) whether they have one.
  void trace(unsigned count, std::span<RTCRayHit16> rays, bool occlusion_only, const RayStart& from) const;
  std::shared_ptr<const Bvh> bvh_;
  std::vector<Mesh> meshes_;
  Options options_;
  float radius_ = 0;
  double d_max_ = 0, tau_ = 0, normalization_ = 1;
};

// The per-sample key of a point: seed, instance (or texture) and element mixed so that neighbours'
// sequences are decorrelated by the scramble.
inline std::uint64_t sample_key(std::uint64_t seed, std::uint64_t group, std::uint64_t element) {
  return seed * 0x100000001b3ull ^ (group << 40) ^ element;
}

}  // namespace matbake::ao
