#pragma once
// Meshes with known geometry for the bake's tests: a unit icosphere, and one laid out for baking
// (each triangle its own UV island in a grid of cells).
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace matbake::test {

// The icosahedron with each triangle split in four `subdivisions` times, new vertices pushed out to
// the unit sphere; counter-clockwise seen from outside.
struct Icosphere {
  std::vector<glm::dvec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};
Icosphere icosphere(int subdivisions);

// An icosphere's triangles corner by corner (vertex 3k + c is corner c of triangle k), triangle k
// mapped into cell (k mod cells, k div cells) of a cells × cells grid at (0.1, 0.1), (0.9, 0.1),
// (0.1, 0.9) of the cell; normals radial (smooth) or the face's (flat).
struct AtlasMesh {
  std::vector<glm::dvec3> positions, normals;
  std::vector<glm::vec2> texcoords;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  int cells = 0;
};
inline constexpr double kAtlasCorner[3][2] = {{0.1, 0.1}, {0.9, 0.1}, {0.1, 0.9}};
AtlasMesh icosphere_atlas(int subdivisions, bool flat);

}  // namespace matbake::test
