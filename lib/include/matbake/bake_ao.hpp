#pragma once
// `matbake bake-ao`, and the AO that `export` and a build's scenes bake with it: a scene's ambient
// occlusion (ao.hpp's estimator over the scene's instances) written into the glTF again, per vertex
// or as occlusion textures over the UVs.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "matbake/ao.hpp"
#include "matbake/delivery.hpp"
#include "matbake/image.hpp"
#include "matbake/result.hpp"

namespace matbake::bake_ao {

// One material's baked occlusion texture.
struct TextureReport {
  int material = -1;  // as written (with per-instance bakes, a copy's index for further placements)
  int node = -1;      // with per-instance bakes, the placing node
  std::string name;   // the material's
  std::string file;   // the new image's URI (beside a .gltf, or embedded in a .glb)
  int width = 0, height = 0, texcoord = 0;
  std::size_t covered = 0, touched = 0, overlapped = 0, padded = 0;  // texels (ao::TextureBake)
  std::size_t triangles = 0, degenerate_uv = 0, wrapped = 0, too_large = 0, instances_without_uv = 0;
  std::string existing;  // what happened to the material's own occlusion texture: "", "multiplied", "replaced"
                         // (each saying when it had a KHR_texture_transform)
  std::string orm;       // with ORM asked for, why the bake was kept apart from metallic-roughness; "" otherwise
  double mean = 0;       // of the bake (before any multiplication), over covered and touched texels
};

// `matbake bake-ao`: a scene's per-vertex AO (or, with ao.texture, its occlusion textures) written into the scene again (everything else kept as
// written: nothing pruned or converted) and/or dumped as raw values (ao::write_dump). Neither output
// may be a file the scene is read from.
struct Options {
  ao::Request ao;
  std::filesystem::path output;  // .gltf or .glb; empty: none
  std::filesystem::path dump;    // .csv or .bin; empty: none (per-vertex only)
  image::Encoding encoding;      // of the occlusion textures' PNGs
  delivery::Options delivery;    // sizes and KTX2 of every texture the written scene uses
};
struct Report {
  std::size_t instances = 0;
  std::size_t vertices = 0;  // baked
  std::uint64_t rays = 0;
  double seconds = 0;        // of the bake: setup_seconds + ray_seconds
  double setup_seconds = 0;  // normals, edge lengths, Embree's BVH
  double ray_seconds = 0;    // casting the rays
  double max_distance = 0;   // d_max as used
  double mean = 0;           // over baked vertices (or mapped texels)
  std::vector<TextureReport> textures;  // with --texture
  std::uint64_t texels = 0;             // traced, with --texture
  double texel_seconds = 0;             // rasterizing UVs and padding, with --texture
  std::vector<std::string> geometry;  // compressed or sparse geometry: decoded to read, and written
                                      // back as it came or uncompressed (gltf::geometry_notes)
  std::vector<std::string> notes;    // the scene's (what was skipped) and the bake's
  std::vector<std::string> written;  // files
  std::vector<delivery::TextureReport> delivered;  // what delivery did to each used texture
};
Result<Report> bake_file(const std::filesystem::path& input, const Options& options);

}  // namespace matbake::bake_ao
