#pragma once
// Baking a high-poly surface onto a low-poly one's UVs, as Substance's, Marmoset's and Blender's
// "selected to active" bakers do. For each texel of the low-poly (the texels of ao::TextureTarget:
// covered and touched, several positions over the footprint for anti-aliasing), one ray from the
// cage toward the low-poly: it starts on the cage (the low-poly pushed `front` out along its
// normals averaged where split vertices meet, Options::average_normals; or a cage mesh) and ends
// `back` beyond the low-poly's point; its first hit on the front of a high-poly face is the texel's
// sample, and every map is computed from it. A ray that finds nothing is a miss: counted, and the
// texel takes its nearest hit neighbour's value.
//
// Only UVs in each target's tile are baked (TextureTarget::tile_origin: the 0–1 tile unless a UDIM
// tile's); a shell moved out by whole tiles is not wrapped back in.
//
// The tangent-space normal map is made for the basis a runtime shades with, so that it gives back
// the high-poly's normal: per vertex the low-poly's TANGENT (MikkTSpace where the file has none, in
// glTF's sign convention) and NORMAL, carried to world space; B = normalize(w · cross(N, T)) per
// vertex; T, B and N interpolated and normalized per texel; the runtime's normal is
// normalize(T·x + B·y + N·z) of the decoded texel (three.js's rule with vertex tangents). The
// texel holds the (x, y, z) that gives the high-poly's normal back exactly: the basis is inverted,
// not transposed, so a basis that is not orthogonal costs nothing.
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "matbake/ao.hpp"
#include "matbake/enum_names.hpp"
#include "matbake/image.hpp"
#include "matbake/result.hpp"
#include "matbake/scene.hpp"

namespace matbake::bake {

enum class Map {
  normal,    // tangent-space normal, RGB in [0, 1] as stored (x/2 + ½ ...)
  height,    // signed distance from the low-poly to the high-poly along the low-poly's normal
             // (positive outside), scene units
  position,  // the hit's world position, scene units
  curvature, // the high-poly's mean curvature at the hit, 1/scene units, positive where convex
  ao,        // ambient occlusion (ao.hpp's estimator) at the hit, over the hemisphere of the
             // high-poly's normal there, the whole high-poly occluding: in [0, 1], 1 open
  bent_normal,  // the mean open direction of those rays (cosine-weighted, μ-weighted), in the
                // low-poly's tangent basis as the normal map stores it
  thickness,    // the high-poly's depth below the hit: the mean over cosine-weighted rays into it
                // (around −normal, either face counting) of distance × cosine (d_max where nothing
                // is met), scene units; a slab of thickness t gives t for every ray
  transfer,     // the high-poly's base colour at the hit (BaseColor below), linear RGBA
  id,           // the material of the texel's first hit, as id_color's RGB (no blending: a mask)
  mask,         // what the texel's rays did, as shares of them: hit (R), missed (G), started inside a
                // closed part (B, counted among the hits); 0 where nothing is traced. Neither
                // filled nor padded: it shows the misses the other maps hide
};
inline constexpr NameTable<Map, 10> kMapNames{{{Map::normal, "normal"},
                                              {Map::height, "height"},
                                              {Map::position, "position"},
                                              {Map::curvature, "curvature"},
                                              {Map::ao, "ao"},
                                              {Map::bent_normal, "bent_normal"},
                                              {Map::thickness, "thickness"},
                                              {Map::transfer, "transfer"},
                                              {Map::id, "id"},
                                              {Map::mask, "mask"}}};
int channels(Map map);
// The maps a low-poly vertex can take (one value each: ao, thickness, curvature, height).
bool per_vertex(Map map);

// The id map's colour of id `id` (a material or primitive number): hue = frac(id × 0.618034) (the
// golden ratio keeps neighbours apart), saturation 0.75, value 0.9; grey 0.5 for none (−1).
glm::vec3 id_color(int id);

// Each instance's glTF primitive number: its (mesh, primitive) pair's place in order among the
// pairs `scene` places (two placements of one primitive share it).
std::vector<int> primitive_numbers(const scene::Scene& scene);

// Which way the normal map's green channel points: OpenGL's (and glTF's) up the texture, against
// the direction of increasing v; DirectX's down it.
enum class Green { opengl, directx };
inline constexpr NameTable<Green, 2> kGreenNames{{{Green::opengl, "opengl"}, {Green::directx, "directx"}}};

// What the id map colours: the hit's material, or its glTF primitive (mesh m's primitive p,
// numbered in (mesh, primitive) order among those the high-poly's scene places).
enum class IdSource { material, primitive };
inline constexpr NameTable<IdSource, 2> kIdSourceNames{{{IdSource::material, "material"}, {IdSource::primitive, "primitive"}}};

// Which high-poly parts a low-poly part's rays meet (Substance's "Match", Marmoset's bake groups):
// every one, or those of the same name: a part's name (its node's, else its mesh's) up to its
// first "_low" (low-poly) or "_high" (high-poly), the whole name where it has none, compared
// case-sensitively: body_low and body_low_2 meet body_high and body_high_top, not Body_high nor
// body_top_high. Parts close together then bake as if exploded apart.
enum class Match { always, by_name };
inline constexpr NameTable<Match, 2> kMatchNames{{{Match::always, "always"}, {Match::by_name, "by_name"}}};

// With Match::by_name, what a hit's AO, bent-normal and thickness rays meet: its own part's
// surfaces (as an exploded bake) or every part's (the contact shadows of the parts beside it).
enum class Occluders { matched, all };
inline constexpr NameTable<Occluders, 2> kOccluderNames{{{Occluders::matched, "matched"}, {Occluders::all, "all"}}};

struct Options {
  std::vector<Map> maps = {Map::normal};
  // Per low-poly vertex (per_vertex maps): one ray from the cage along the vertex's normal, the
  // map's value at its hit as a texel's (VertexBake).
  std::vector<Map> vertex_maps;
  // The cage: how far outside (front) and inside (back) the low-poly the rays reach, as fractions
  // of the low-poly's bounding-box diagonal, or in scene units when absolute.
  double front = 0.01, back = 0.01;
  // With Match::by_name, a part's own front and back (by its key, part_key(name, "_low")), as
  // front and back count them: a bolt that stands far above its plate, a strap that hugs a sleeve.
  std::map<std::string, double, std::less<>> front_by_part, back_by_part;
  bool absolute_distances = false;
  Green green = Green::opengl;
  IdSource id_by = IdSource::material;
  std::uint64_t seed = 0;  // of the anti-aliasing positions
  Match match = Match::always;
  Occluders occluders = Occluders::matched;  // with Match::by_name
  // Without a cage mesh: the cage is the low-poly pushed out by `front` along normals averaged where
  // its split vertices meet (averaged_normal_cage), rays heading from it for the low-poly's point,
  // as Substance's "average normals" and Blender's extrusion of a welded mesh. Along a hard edge the
  // two sides' rays then sweep the high-poly between them with neither gap nor overlap; where the
  // low-poly has no split normals the rays are the extrusion's.
  bool average_normals = true;
  // The normal map's normal at a hit: the high-poly's own normal map applied there (HighMaterials::
  // normals), as a runtime shades the high-poly, instead of its interpolated vertex normal.
  bool high_normal_maps = false;
};

Status check(const Options& options);

// The cage's front and back distances in scene units (Options's fractions of the low-poly's
// bounding-box diagonal, or as given with absolute_distances). With a cage mesh, front is the
// farthest any low-poly vertex lies from its cage vertex (the extrusion's where it touches them all).
std::pair<double, double> cage_distances(const scene::Scene& low, const Options& options, const scene::Scene* cage = nullptr);

// Why `cage` cannot be the cage of `low` (empty when it can): it must place the low-poly's
// primitives in the same order with the same vertex count and triangles (its positions moved).
std::string cage_mismatch(const scene::Scene& low, const scene::Scene& cage);

// The cage of Options::average_normals: per low instance k, its positions (and nothing else) each
// moved front[k] along the mean of the distinct normals of the vertices at that position.
scene::Scene averaged_normal_cage(const scene::Scene& low, const std::vector<double>& front);

// Per low instance, its front and back in scene units (Options::front_by_part and back_by_part of
// its part's key, else front and back; scaled as cage_distances scales them). `unknown`: why a
// part named in those tables is none of the low-poly's (a misspelt name), else empty.
struct CageReach {
  std::vector<double> front, back;
  std::string unknown;
};
CageReach part_distances(const scene::Scene& low, const Options& options);

struct Bake;
// Whether the cage (bake.front and back as cage_distances gives them, and each part's `reach`)
// stays within kDeepestCage times the larger of the two meshes' diagonals (bake.boxes): beyond it
// a ray meets nothing a bake wants, its start loses float precision, and far enough Embree refuses
// it (an abort). A usage error naming the options.
constexpr double kDeepestCage = 100;
Status check_depth(const Bake& bake, const CageReach& reach);

// A high-poly material's texture as a runtime samples it: through its UV set and transform,
// bilinear, with its sampler's wrap modes.
struct MaterialTexture {
  image::Image image;
  int texcoord = 0;
  std::function<glm::dvec2(glm::dvec2)> transform;  // the texture's UV transform; empty: none
  Wrap wrap_s = Wrap::repeat, wrap_t = Wrap::repeat;
};

// A high-poly material's base colour as a runtime shades it: factor × texture × COLOR_0 (linear).
struct BaseColor {
  glm::vec4 factor{1.0f};
  std::optional<MaterialTexture> texture;  // linear RGBA floats (colour channels decoded from sRGB)
};

// A high-poly material's normalTexture (Options::high_normal_maps): its codes as stored (linear,
// 0–1), decoded as glTF says: n = (2c − 1) with x and y times `scale`, in the high-poly's tangent
// basis at the hit (its TANGENT, else MikkTSpace's), normalized.
struct NormalTexture {
  MaterialTexture texture;
  double scale = 1;
};

// What the high-poly's materials give the maps, one entry per material index (an instance without
// a material, or beyond them, has none): base colours for transfer, normal maps for the normal map.
struct HighMaterials {
  std::vector<BaseColor> base_colors;
  std::vector<std::optional<NormalTexture>> normals;
};

struct MapImage {
  Map map = Map::normal;
  int channels = 0;
  std::vector<float> values;  // width × height × channels, row-major
};

// A part's name up to the first `suffix` ("_low" or "_high"), or the whole name without one.
std::string_view part_key(std::string_view name, std::string_view suffix);

// The parts Match::by_name pairs: a number per low and per high instance, equal where they meet (a
// low part no high part matches has a number no high instance has); `unmatched` names those low
// parts, each once, in order.
struct PartMatch {
  std::vector<std::uint32_t> low, high;
  std::vector<std::string> unmatched;
};
PartMatch match_parts(const scene::Scene& low, const scene::Scene& high);

struct TextureBake {
  int width = 0, height = 0;
  std::vector<MapImage> maps;     // in the order of Options::maps
  std::vector<std::uint8_t> hit;  // per texel: 1 where a ray found the high-poly
  std::size_t texels = 0;         // traced (covered or touched)
  std::size_t samples = 0, misses = 0;  // rays cast, and how many found nothing
  std::size_t occlusion_rays = 0;       // cast from the hits, for ao, bent_normal and thickness
  std::size_t missed_texels = 0;        // texels all of whose rays missed: filled from neighbours
  std::size_t padded = 0;
  double height_min = 0, height_max = 0;  // over the hits
  std::size_t from_inside = 0;   // rays whose first surface was a high-poly face's back (a start inside a closed part)
  std::size_t overlapped = 0;    // texels whose centre several triangles cover (overlapping islands): their mean
  std::size_t outside_tile = 0;  // triangles whose UVs lie wholly outside the target's tile (or are not finite): not baked
  std::size_t degenerate_uv = 0, too_large = 0;  // triangles skipped: UVs of no area or not finite; spanning too far
  std::size_t faced_away = 0;    // missed rays that met only the backs of high-poly faces (flipped winding)
  // The cage reach, scene units, that would have met 95% of the missed rays a probe along the
  // low-poly's normal (the low-poly's diagonal either way) found the high-poly for: outside (front,
  // as Options::front counts it: the averaged cage moves a point less far along its normal than
  // front; with a cage mesh, how much farther out it must lie) and inside (back); 0 where none.
  double reach_front = 0, reach_back = 0;
};

// Options::vertex_maps at each vertex of each low-poly instance: the cage ray from the vertex (its
// cage vertex, the cage mesh's or the averaged cage's, or else `front` out along its normal: the
// file's, else area-weighted) to `back` inside,
// the map's value at the hit as a texel with one position computes it (ao and thickness: the
// estimator's samples from the hit, keyed by instance and vertex). A vertex whose ray misses takes
// the mean of its hit neighbours (sharing a triangle), repeatedly outwards; where none is reached,
// the background (ao 1, others 0).
struct VertexBake {
  std::vector<Map> maps;                                // Options::vertex_maps
  std::vector<std::vector<std::vector<float>>> values;  // per map, per low instance, per vertex
  std::size_t vertices = 0, misses = 0;                 // rays cast (one a vertex), and missed
  std::size_t occlusion_rays = 0;
};

// The two meshes' bounding boxes, which tell a units or placement mistake from a small cage.
struct Boxes {
  double low_diagonal = 0, high_diagonal = 0;
  double overlap = 1;  // the least, over the axes, share of the low-poly's extent the high-poly's covers
};
Boxes compare_boxes(const scene::Scene& low, const scene::Scene& high);

// The likely cause of a texture's misses, a clause: the boxes' sizes differ by a power of ten
// (units), they barely overlap (placement or the wrong file), or else the cage, with the front and
// back that would have reached (in `options`'s terms: fractions of `diagonal`, or scene units).
// With a cage mesh (`cage_mesh`), the reach is how much farther out the mesh must lie.
std::string miss_cause(const Boxes& boxes, const TextureBake& texture, const Options& options, double diagonal,
                       bool cage_mesh = false);

struct Bake {
  Boxes boxes;
  std::vector<TextureBake> textures;  // one per target
  VertexBake vertices;                // with Options::vertex_maps
  std::vector<std::string> unmatched;  // with Match::by_name: low parts no high part matches (all rays miss)
  double front = 0, back = 0;         // the cage distances used, scene units
  double setup_seconds = 0, trace_seconds = 0;
};

// `low` must have been loaded with SceneContent::object_space and texcoords (the tangents are
// computed from the file's own attributes); `high` is used in world space. `occlusion` is the
// estimator of the ao, bent_normal and thickness maps (thickness: two-sided, its falloff unused): its samples are a texel's rays, shared among its
// texel_samples positions as the AO texture bake shares them (position j casts rays j, j + K, ...);
// its distances are of the high-poly's radius. The result is the same for any number of threads.
// Errors: options out of range, a target without its UV set's data, Embree failing.
// `materials` holds the high-poly's base colours (the transfer map's: an instance without one is
// white) and, with Options::high_normal_maps, its normal maps; either needs the high-poly's
// texcoords loaded, normal maps its object-space attributes too (SceneContent::object_space).
// With a `cage` mesh (cage_mismatch empty), each ray starts at the cage's point with the low-poly
// point's barycentric weights and heads for the low-poly point, reaching `back` beyond it; where
// the two coincide, the ray is the extrusion's (Options::front along the low-poly's normal).
Result<Bake> bake(const scene::Scene& low, const scene::Scene& high, const std::vector<ao::TextureTarget>& targets,
                  const ao::TextureOptions& texture, const Options& options, const ao::Options& occlusion = {},
                  const HighMaterials& materials = {}, const scene::Scene* cage = nullptr);

}  // namespace matbake::bake
