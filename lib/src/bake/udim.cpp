#include "udim.hpp"

#include <cmath>
#include <set>

#include "../gltf/split_primitive.hpp"
#include "frames.hpp"
#include "matbake/bake_file.hpp"

namespace matbake::bake {

int udim_of(glm::dvec2 uv) {
  const double column = std::floor(uv.x), row = std::floor(1.0 - uv.y);
  if (!(column >= 0 && column < 10 && row >= 0 && row < 100)) return 0;  // NaN fails too
  return 1001 + int(column) + 10 * int(row);
}

glm::ivec2 udim_origin(int tile) { return {(tile - 1001) % 10, -((tile - 1001) / 10)}; }

// A quarter of a texel at 2048: a corner on a border (an island's edge laid on it) is inside.
constexpr double kSlack = 1e-4;

int udim_of(const glm::vec2& a, const glm::vec2& b, const glm::vec2& c) {
  const int tile = udim_of((glm::dvec2(a) + glm::dvec2(b) + glm::dvec2(c)) / 3.0);
  if (tile == 0) {  // outside every tile, unless a corner lies inside one: across the tiles' outer edge
    for (const glm::vec2& corner : {a, b, c}) {
      const double u = corner.x, up = 1.0 - double(corner.y);
      if (u > kSlack && u < 10 - kSlack && up > kSlack && up < 100 - kSlack) return kAcrossTiles;
    }
    return 0;
  }
  const glm::dvec2 low(udim_origin(tile));
  for (const glm::vec2& corner : {a, b, c}) {
    const glm::dvec2 p(corner);
    if (p.x < low.x - kSlack || p.x > low.x + 1 + kSlack || p.y < low.y - kSlack || p.y > low.y + 1 + kSlack) return kAcrossTiles;
  }
  return tile;
}

Result<TileTargets> udim_targets(const scene::Scene& low, const std::vector<ao::TextureTarget>& targets) {
  TileTargets out;
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const ao::TextureTarget& target = targets[t];
    std::set<int> tiles;
    std::size_t outside = 0;
    for (std::size_t k : target.instances) {
      const scene::Instance& inst = low.instances[k];
      if (std::size_t(target.texcoord) >= inst.texcoords.size()) continue;  // not a target's (material_targets)
      const auto& uv = inst.texcoords[std::size_t(target.texcoord)];
      for (std::size_t i = 0; i < inst.triangles.size(); ++i) {
        const auto& c = inst.triangles[i];
        const int tile = udim_of(uv[c[0]], uv[c[1]], uv[c[2]]);
        if (tile == kAcrossTiles) {
          return Error{"", target.name + ": triangle " + std::to_string(i) + " of mesh " + std::to_string(inst.mesh) + " primitive " +
                               std::to_string(inst.primitive) + " lies across a UDIM tile's border, and a glTF triangle "
                               "takes one tile's images: keep each UV island inside one tile (or bake without udim)"};
        }
        if (tile == 0) ++outside;
        else tiles.insert(tile);
      }
    }
    if (outside) {
      out.notes.push_back(target.name + ": " + std::to_string(outside) + " triangles lie outside the UDIM tiles (u from 0 to "
                          "10, v up from 0 to 100): not baked");
    }
    if (tiles.empty()) tiles.insert(1001);  // its maps hold fill values: the bake warns of it
    for (int tile : tiles) {
      ao::TextureTarget& made = out.targets.emplace_back(target);
      made.tile_origin = udim_origin(tile);
      made.name += " tile " + std::to_string(tile);
      out.from.push_back(t);
      out.tiles.push_back(tile);
    }
    if (out.targets.size() > std::size_t(kMaxUdimTiles)) {
      return Error{"", "the low-poly's materials touch " + std::to_string(out.targets.size()) + " UDIM tiles or more (" +
                           target.name + ": " + std::to_string(tiles.size()) + "), more than the " +
                           std::to_string(kMaxUdimTiles) + " one bake holds (each tile's maps are held until written): "
                           "bake the materials one at a time, or move the UVs into fewer tiles"};
    }
  }
  return out;
}

Status split_by_tile(gltf::Document& doc, const scene::Scene& low, const TileTargets& split, const std::vector<int>& materials,
                     const std::map<std::pair<int, int>, std::vector<std::uint32_t>>& written) {
  std::set<std::pair<int, int>> done;  // (mesh, primitive): split once, whichever placement comes first
  for (std::size_t first = 0, last = 0; first < split.targets.size(); first = last) {
    std::map<int, int> material_of;  // tile → material
    for (last = first; last < split.targets.size() && split.from[last] == split.from[first]; ++last) {
      material_of[split.tiles[last]] = materials[last];
    }
    const ao::TextureTarget& target = split.targets[first];
    for (std::size_t k : target.instances) {
      const scene::Instance& inst = low.instances[k];
      const int mesh = doc.json["nodes"][std::size_t(inst.node)]["mesh"].get<int>();
      if (!done.insert({mesh, inst.primitive}).second) continue;
      const auto& uv = inst.texcoords[std::size_t(target.texcoord)];
      const auto renumbered = written.find({mesh, inst.primitive});
      std::map<int, gltf::TriangleGroup> by_tile;
      for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
        const auto& c = inst.triangles[t];
        int tile = udim_of(uv[c[0]], uv[c[1]], uv[c[2]]);
        if (!material_of.contains(tile)) tile = split.tiles[first];  // outside every tile: with the first
        gltf::TriangleGroup& group = by_tile[tile];
        group.material = material_of[tile];
        if (renumbered != written.end()) {
          const std::uint32_t* corners = &renumbered->second[3 * t];
          group.triangles.push_back({corners[0], corners[1], corners[2]});
        } else {
          group.triangles.push_back(file_triangle(inst, t));
        }
      }
      std::vector<gltf::TriangleGroup> groups;
      for (auto& [tile, group] : by_tile) groups.push_back(std::move(group));
      if (Status s = gltf::split_primitive(doc, mesh, inst.primitive, groups); !s) return s;
    }
  }
  return success();
}

}  // namespace matbake::bake
