#pragma once
// `matbake bake LOW --from HIGH -o OUT`: the high-poly's maps baked onto the low-poly's UVs, one
// texture set per low-poly material (bake.hpp), and the low-poly written again with them: the
// normal map as the material's normalTexture (with TANGENT written, so that every runtime shades
// in the basis it was baked in), AO as its occlusionTexture, the other maps as float EXR files
// beside the output.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "matbake/bake.hpp"
#include "matbake/image.hpp"

namespace matbake::bake {

// How the maps that are not the material's own textures (all but normal, ao and transfer) are
// written beside the output: float EXR, or PNG with each map's values mapped onto 0–1 (map_range).
enum class MapFormat { exr, png };
inline constexpr NameTable<MapFormat, 2> kMapFormatNames{{{MapFormat::exr, "exr"}, {MapFormat::png, "png"}}};

struct Request {
  Options bake;
  ao::TextureOptions texture{.width = 1024, .height = 1024, .padding = -1, .texel_samples = 4};
  ao::Request occlusion;  // the ao, bent_normal and thickness maps' estimator: its `options` (ao_params.hpp's estimator_params)
  ao::Into vertex_ao_into = ao::Into::attribute;  // where per-vertex AO goes (the other vertex maps: _THICKNESS, ...)
  // A mesh placed by several nodes: its texels and vertices hold the mean of the placements (false),
  // or each placement gets its own copy of the mesh and material and its own maps (true).
  bool per_instance = false;
  // The share of a material's rays (or of the vertices' rays) that may miss the high-poly before the
  // bake fails: a units or placement mistake misses nearly all; a sound bake a few percent, and the
  // roughest pair the tests bake (a Khronos model onto its 10% simplification) 28%.
  double max_misses = 0.5;
  int bits = 8;  // of every PNG the bake writes: the material's textures, and the maps beside with MapFormat::png
  MapFormat map_format = MapFormat::exr;
  // Every UDIM tile a material's UVs touch baked into maps of its own, named
  // <stem>_<material>_<map>.<tile> (tile 1001 + u + 10·v, v counted up the texture as Mari and
  // Blender count it); in the glTF, one material per tile, each primitive split by tile, as
  // Blender's glTF exporter writes UDIMs. A triangle across a tile's border is refused.
  bool udim = false;
};
constexpr int kMaxUdimTiles = 100;  // in one bake: each tile's maps are held until written

// The values a PNG map's 0 and 1 stand for (MapFormat::png): the encoded maps (normal, bent
// normal, ao, transfer, id, mask) as they are, 0 to 1; height and curvature symmetric about 0 (½ is
// 0), to the largest magnitude baked; thickness 0 to its largest; position the smallest to the
// largest coordinate of any axis (one scale for all three). A map of one value spans 1 around it.
std::pair<double, double> map_range(const MapImage& image);

// check(Options), and what a glTF cannot hold: green directx with the normal map (a glTF's
// normalTexture is OpenGL's convention; every viewer would shade it inverted).
Status check(const Request& request);

struct FileOptions {
  std::filesystem::path high;    // .gltf or .glb: the surface the maps come from
  std::filesystem::path cage;    // .gltf or .glb: the low-poly with its vertices moved out (empty: extrusion)
  std::filesystem::path output;  // .gltf or .glb
  Request request;
  image::Encoding encoding;      // of the normal map's PNG
  // Where the maps are kept between bakes (a build's state folder; empty: nowhere): a map whose
  // inputs and parameters are those it was kept with is read back, not traced (docs/bake.md).
  std::filesystem::path keep;
};

struct TextureReport {
  int material = -1;
  std::string name;                // the material's
  std::string copy_of;             // per_instance, udim: the name of the material a placement's or tile's copy copies
  int copy_of_material = -1;       // and its index (−1: not a copy)
  int width = 0, height = 0, texcoord = 0;
  int tile = 0;                    // with Request::udim, the UDIM tile (1001, ...); else 0
  std::size_t texels = 0, samples = 0, misses = 0, missed_texels = 0, padded = 0, occlusion_rays = 0;
  double height_min = 0, height_max = 0;
  std::size_t from_inside = 0, overlapped = 0, outside_tile = 0, faced_away = 0;  // bake.hpp's TextureBake
  std::size_t skipped_triangles = 0;  // UVs of no area, not finite, or spanning too far
  std::vector<std::string> files;  // per map, in the order asked: the image's URI or the file written
  std::vector<std::optional<std::pair<double, double>>> ranges;  // per map: what its PNG's 0 and 1 stand for; none for EXR
  std::string existing;            // what happened to the material's own normalTexture and occlusionTexture
                                   // ("", "normal replaced", "occlusion replaced", both)
};

struct VertexReport {
  std::size_t vertices = 0, misses = 0, occlusion_rays = 0;  // of the low-poly instances
  std::vector<std::string> attributes;                       // written, per vertex map asked
};

struct FileReport {
  std::vector<TextureReport> textures;
  VertexReport vertices;               // with vertex maps
  std::size_t tangent_primitives = 0;  // primitives given TANGENT
  std::size_t split_vertices = 0;      // vertices added where corners needed different tangents
  double front = 0, back = 0;          // the cage, scene units
  double seconds = 0, setup_seconds = 0, trace_seconds = 0;
  std::vector<std::string> notes;
  std::vector<std::string> warnings;   // misses and rays that started inside a part, per material, with the likely cause
  std::vector<std::string> written;    // files
  std::vector<std::string> beside;     // those of them the glTF does not reference: the float maps
  std::vector<std::string> reused;     // maps read back from FileOptions::keep, not traced
};

// Errors: either file unreadable (named), an output onto an input, no low-poly material with the
// UV set, options out of range, a material's (or the vertices') share of missed rays above
// Request::max_misses (naming the likely cause).
Result<FileReport> bake_file(const std::filesystem::path& low, const FileOptions& options);

}  // namespace matbake::bake
