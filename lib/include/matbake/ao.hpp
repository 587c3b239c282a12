#pragma once
// Per-vertex ambient obscurance (ch. 12, eq. 12.72) ray-cast with Embree 3:
//   w(p) = (1/π) ∫ μ(d(ω)) cos θ dω
// over the hemisphere around the vertex normal, d the distance to the first surface along ω.
// μ is normalized to the range d_max so that it reaches 1 there and open sky gives w = 1:
//   exponential: μ(x) = (1 − e^(−τx)) / (1 − e^(−τ d_max)) for x < d_max, 1 beyond;
//   none (binary AO): μ = 0 for a hit within d_max, 1 beyond.
// With cosine-weighted directions (pdf cos θ / π) the estimator is the mean of μ over the rays.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "matbake/result.hpp"
#include "matbake/scene.hpp"

namespace matbake::ao {

enum class Falloff { exponential, none };
enum class Sampler {
  sobol,   // (0, 2)-sequence in base 2, XOR-scrambled per vertex: low discrepancy
  random,  // independent uniform pairs per vertex: for comparison
};

struct Options {
  int samples = 64;                // rays per vertex
  double max_distance = 0.25;      // d_max: absolute, or × the scene radius when relative_distance
  bool relative_distance = true;
  double tau = 4.0;                // τ in units of 1/d_max (so e^(−τ d_max) = e^(−4) by default)
  Falloff falloff = Falloff::exponential;
  double bias = 1e-5;  // origin offset along the normal, × the vertex's mean edge length, capped at
                       // 1e-4 × the scene radius, at least 1e-6 × the vertex's coordinates' magnitude
  bool two_sided = true;           // false: surfaces seen from behind do not occlude
  std::uint64_t seed = 0;
  Sampler sampler = Sampler::sobol;
  std::vector<bool> targets;  // per instance: bake it (all occlude either way); empty: all
  // Embree's robust traversal: no ray slips between two triangles sharing an edge (without it, 1
  // ray in 256 leaked out of a closed box from its corners). Costs about a third of the speed.
  bool watertight = true;
};

struct Bake {
  std::vector<std::vector<float>> values;  // per scene instance, per vertex: w in [0, 1] (empty: not a target)
  std::uint64_t rays = 0;
  double max_distance = 0;                 // d_max as used (absolute)
};

// Normals: the instance's own where present, else area-weighted from its faces. Identical for a
// given seed whatever the thread count (each vertex has its own sample stream).
Result<Bake> bake(const scene::Scene& scene, const Options& options);

// Raw values: `.csv` (a header, then node,mesh,primitive,vertex,x,y,z,ao per baked vertex, world
// positions) or `.bin` (the float32 values, little-endian, in the same order). Written atomically.
Status write_dump(const std::filesystem::path& path, const scene::Scene& scene, const Bake& bake);

// Where the values go in a written glTF.
enum class Into {
  color,           // COLOR_0 = (w, w, w): the renderer multiplies the base colour by it
  color_multiply,  // COLOR_0 = the file's COLOR_0 × w (alpha kept); (w, w, w) where there is none
  attribute,       // `_AO`, one float per vertex (an application-specific attribute)
};

// Writes the scene file `input` again as `output` (.gltf with a .bin beside it, or .glb; either
// from either) with each baked primitive's values in it; everything else is kept as written. A
// mesh placed by several nodes gets a copy per further node (sharing every accessor but the new
// one), because each placement has its own occlusion. `scene` must be load_scene(input).
Status write_gltf(const std::filesystem::path& input, const scene::Scene& scene, const Bake& bake, Into into,
                  const std::filesystem::path& output);

// Sample i of the per-vertex sequence, in [0, 1)².
struct Sample2 {
  float u, v;
};
Sample2 sample(Sampler sampler, std::uint32_t i, std::uint64_t vertex_key);

}  // namespace matbake::ao
