#pragma once
// Per-vertex ambient obscurance (ch. 12, eq. 12.72) ray-cast with Embree 3:
//   w(p) = (1/π) ∫ μ(d(ω)) cos θ dω
// over the hemisphere around the vertex normal, d the distance to the first surface along ω.
// μ is normalized to the range d_max so that it reaches 1 there and open sky gives w = 1:
//   exponential: μ(x) = (1 − e^(−τx)) / (1 − e^(−τ d_max)) for x < d_max, 1 beyond;
//   none (binary AO): μ = 0 for a hit within d_max, 1 beyond.
// With cosine-weighted directions (pdf cos θ / π) the estimator is the mean of μ over the rays.
#include <glm/vec2.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "matbake/enum_names.hpp"
#include "matbake/result.hpp"
#include "matbake/scene.hpp"
#include "matbake/stage.hpp"
#include "matbake/wrap.hpp"

namespace matbake::ao {

enum class Falloff { exponential, none };
inline constexpr NameTable<Falloff, 2> kFalloffNames{{{Falloff::exponential, "exponential"}, {Falloff::none, "none"}}};

enum class Sampler {
  sobol,   // (0, 2)-sequence in base 2, XOR-scrambled per vertex: low discrepancy
  random,  // independent uniform pairs per vertex: for comparison
};
inline constexpr NameTable<Sampler, 2> kSamplerNames{{{Sampler::sobol, "sobol"}, {Sampler::random, "random"}}};

// Every option of the estimator, with its default: `bake-ao`, `export --ao-*` and a manifest's
// `ao = { ... }` fill this struct and nothing else decides a default.
struct Options {
  int samples = 64;                 // rays per vertex, 1 to kMaxSamples
  double relative_distance = 0.25;  // d_max as a fraction of the scene radius ...
  double absolute_distance = 0;     // ... or, when > 0, in scene units
  double tau = 4.0;                 // τ in units of 1/d_max (so e^(−τ d_max) = e^(−4) by default)
  Falloff falloff = Falloff::exponential;
  double bias = 1e-5;  // origin offset along the normal, × the vertex's mean edge length, capped at
                       // 1e-4 × the scene radius, at least 1e-6 × the vertex's coordinates' magnitude
  bool two_sided = false;           // false: surfaces seen from behind (by their winding) do not occlude
  std::uint64_t seed = 0;
  Sampler sampler = Sampler::sobol;
  // Normals the rays start around: the file's (area-weighted from the faces where it has none), or
  // recomputed from the faces with this weighting.
  std::optional<scene::NormalWeighting> recompute_normals;
  std::vector<bool> targets;  // per instance: bake it (all occlude either way); empty: all
  // Embree's robust traversal: no ray slips between two triangles sharing an edge (without it, 1
  // ray in 256 leaked out of a closed box from its corners). Costs about a third of the speed.
  bool watertight = true;
};
constexpr int kMaxSamples = 1 << 20;

// The options' ranges (samples, distances, τ, bias); errors name the option as the Options field.
Status check(const Options& options);

struct Bake {
  std::vector<std::vector<float>> values;  // per scene instance, per vertex: w in [0, 1] (empty: not a target)
  std::uint64_t rays = 0;
  double max_distance = 0;                 // d_max as used (absolute)
  double setup_seconds = 0;                // normals, edge lengths and Embree's BVH
  double ray_seconds = 0;                  // casting the rays
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
// As both front ends name it: an attribute ("COLOR_0" or "_AO") and, for COLOR_0, what happens to
// the file's own colours ("multiply" or "replace").
std::string_view into_attribute_name(Into into);
std::string_view into_existing_colors_name(Into into);  // "multiply" for Into::attribute too
std::optional<Into> into_from_names(std::string_view attribute, std::string_view existing_colors);

// --- Texture-space bake -------------------------------------------------------------------------------
// Occlusion over a mesh's UVs, as Blender's, xNormal's or Substance's bakers make it: one texture per
// target, each texel the estimator above at the surface point that its centre maps to.
// Texels, in texture space with texel centres at ((i + ½)/W, (j + ½)/H) and row 0 at v = 0 (glTF's
// top row):
// - covered: the centre lies in a triangle's UV image. A centre on an edge shared by two triangles
//   belongs to one of them (a tie rule on the edge's direction), so a seamless layout maps every
//   centre once.
// - touched: the centre lies outside every triangle but within half a texel diagonal of one; it is
//   sampled at the nearest point of the nearest such triangle, so texels along UV seams hold the
//   surface's value rather than the background.
// - padded: within `padding` texels of a covered or touched one; takes the value of the nearest
//   (ties averaged), so bilinear filtering and mipmaps do not read the background.
// - the rest hold 1 and are never traced.
// A texel mapped by several surfaces (overlapping islands, stacked copies, UVs wrapping past [0, 1],
// a mesh placed by several nodes) holds their mean, and is counted as overlapped.

using matbake::Wrap;  // a glTF sampler's wrapS / wrapT

// One texture: the triangles of some instances through one UV set.
struct TextureTarget {
  std::vector<std::size_t> instances;  // indices into scene.instances
  int texcoord = 0;                    // TEXCOORD_n; an instance without it is skipped and counted
  Wrap wrap_s = Wrap::repeat, wrap_t = Wrap::repeat;  // how the texture will be sampled past [0, 1]
  bool tile_only = false;  // the 0–1 tile alone: what lies outside it is not wrapped in (a high-to-low bake)
  // The UV tile the texture spans, by its corner: [u, u + 1] × [v, v + 1] of the UV set (a UDIM
  // tile's); (0, 0) is the 0–1 tile. With tile_only, that tile alone is baked.
  glm::ivec2 tile_origin{0, 0};
  std::string name = "";  // what errors call this texture ("material 2 'wood'"); empty: "texture N"
};

struct TextureOptions {
  int width = 1024, height = 1024;
  int padding = -1;       // texels; -1: kDefaultPadding at 1024, scaled with the larger side
  int texel_samples = 1;  // surface points per texel, stratified over its footprint; the rays are
                          // shared among them (1 to the sample count)
};
constexpr int kDefaultPadding = 16;
constexpr int kMaxTextureSide = 16384;
int padding_for(const TextureOptions& options);  // the padding used
Status check(const TextureOptions& options, const Options& estimator);
// The same, for a bake of `what` ("AO", "bake") with at most max_texel_samples positions a texel.
Status check(const TextureOptions& options, int max_texel_samples, const std::string& what);

struct TextureBake {
  int width = 0, height = 0;
  std::vector<float> values;  // width × height, row-major; 1 where nothing maps
  // Texel counts.
  std::size_t covered = 0;     // centre inside a triangle
  std::size_t touched = 0;     // centre outside, within half a diagonal of one (nearest point)
  std::size_t overlapped = 0;  // covered by more than one surface
  std::size_t padded = 0;
  // Triangle counts.
  std::size_t triangles = 0;            // rasterized
  std::size_t degenerate_uv = 0;        // zero area in UV (or not finite): skipped
  std::size_t wrapped = 0;              // reaching outside [0, 1]: sampled with the wrap mode
  std::size_t too_large = 0;            // spanning more than 64 copies of the texture: skipped
  std::size_t instances_without_uv = 0; // instances of the target lacking its UV set
  std::uint64_t rays = 0;
  double mean = 0;  // over covered and touched texels
};

struct TextureBakes {
  std::vector<TextureBake> textures;  // one per target, in order
  std::uint64_t rays = 0;
  double max_distance = 0;
  double setup_seconds = 0;   // normals, edge lengths and Embree's BVH
  double texel_seconds = 0;   // cutting the UVs into tiles, padding
  double ray_seconds = 0;     // the tiles: each one's coverage, then its rays
};

// Deterministic for a given seed whatever the thread count. options.targets is ignored (every
// instance occludes; the targets say what is baked).
// `stage` is told as each texture starts.
Result<TextureBakes> bake_textures(const scene::Scene& scene, const Options& options,
                                   const std::vector<TextureTarget>& targets, const TextureOptions& texture,
                                   const StageReport& stage = {});

// Texture bakes for a written glTF: one occlusion texture per material the default scene reaches.
struct TextureRequest {
  TextureOptions size;          // width, height, padding, texel samples
  int texcoord = -1;            // the UV set; -1: the material's occlusionTexture texCoord, else 0
  int bits = 8;                 // linear PNG, 8 or 16 bits
  bool multiply_existing = true;  // an occlusion texture the material has: multiplied, or replaced
  std::filesystem::path dump;   // a folder for each texture as float EXR as well; empty: none
  // A mesh placed by several nodes: one texture averages the placements (false), or each placement
  // gets its own copy of the material and its own texture (true).
  bool per_instance = false;
};
Status check(const TextureRequest& request, const Options& estimator);

// A bake for a written glTF: the estimator's options and where the values go.
struct Request {
  Options options;
  Into into = Into::color_multiply;          // per-vertex values
  std::optional<TextureRequest> texture;     // set: occlusion textures instead of per-vertex values
};

// Sample i of the per-vertex sequence, in [0, 1)².
struct Sample2 {
  float u, v;
};
Sample2 sample(Sampler sampler, std::uint32_t i, std::uint64_t vertex_key);

}  // namespace matbake::ao
