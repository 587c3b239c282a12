#pragma once
// UDIM tiles (Request::udim): which tile each triangle of a low-poly lies in, a texture target per
// tile, and the glTF's primitives split so that each tile's triangles take that tile's material.
#include <glm/vec2.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "../gltf/document.hpp"
#include "matbake/ao.hpp"
#include "matbake/result.hpp"
#include "matbake/scene.hpp"

namespace matbake::bake {

// The UDIM tile of UV point `uv` (glTF's v, down the texture): 1001 + floor(u) + 10·floor(1 − v),
// for u in [0, 10) and 1 − v in [0, 100); 0 outside them (or not finite).
int udim_of(glm::dvec2 uv);
// The tile of a triangle: its UV centroid's; kAcrossTiles where a corner lies beyond that tile by
// more than 1e-4 (an island across a border), or where the centroid lies outside every tile and a
// corner inside one by more than that (across the tiles' outer edge).
constexpr int kAcrossTiles = -1;
int udim_of(const glm::vec2& a, const glm::vec2& b, const glm::vec2& c);
// TextureTarget::tile_origin of a tile: its corner of smallest u and v in glTF's UVs.
glm::ivec2 udim_origin(int tile);

// Each target split into one per tile its triangles lie in, in tile order (`from`: the target it
// came from; `tiles`: its tile). A target no triangle of which lies in a tile keeps tile 1001.
// Errors: a triangle across a tile's border (naming it), more than kMaxUdimTiles tiles.
struct TileTargets {
  std::vector<ao::TextureTarget> targets;
  std::vector<std::size_t> from;
  std::vector<int> tiles;
  std::vector<std::string> notes;  // triangles outside every tile: not baked
};
Result<TileTargets> udim_targets(const scene::Scene& low, const std::vector<ao::TextureTarget>& targets);

// Each glTF primitive the instances of a tile-split target place, its triangles divided by tile:
// tile `tiles[i]` of target `from[i]` takes material `materials[i]` (triangles outside every tile go
// with the target's first tile). `written` holds, per (mesh, primitive) of the document, its
// triangles where writing TANGENT renumbered its vertices (else the file's are used). The mesh is
// the one the instance's node places now (per_instance may have copied it).
Status split_by_tile(gltf::Document& doc, const scene::Scene& low, const TileTargets& split, const std::vector<int>& materials,
                     const std::map<std::pair<int, int>, std::vector<std::uint32_t>>& written);

}  // namespace matbake::bake
