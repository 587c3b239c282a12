#include "support/shapes.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <map>

namespace matbake::test {

using glm::dvec3;

Icosphere icosphere(int subdivisions) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  Icosphere s;
  for (const dvec3& v : {dvec3(-1, g, 0), dvec3(1, g, 0), dvec3(-1, -g, 0), dvec3(1, -g, 0), dvec3(0, -1, g), dvec3(0, 1, g),
                         dvec3(0, -1, -g), dvec3(0, 1, -g), dvec3(g, 0, -1), dvec3(g, 0, 1), dvec3(-g, 0, -1), dvec3(-g, 0, 1)}) {
    s.vertices.push_back(glm::normalize(v));
  }
  s.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
    const auto mid = [&](std::uint32_t a, std::uint32_t b) {
      auto [it, added] = middle.try_emplace(std::minmax(a, b), std::uint32_t(s.vertices.size()));
      if (added) s.vertices.push_back(glm::normalize(s.vertices[a] + s.vertices[b]));
      return it->second;
    };
    std::vector<std::array<std::uint32_t, 3>> finer;
    for (const auto& t : s.triangles) {
      const std::uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      finer.push_back({t[0], ab, ca}), finer.push_back({t[1], bc, ab}), finer.push_back({t[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    s.triangles = std::move(finer);
  }
  return s;
}

AtlasMesh icosphere_atlas(int subdivisions, bool flat) {
  const Icosphere ico = icosphere(subdivisions);
  AtlasMesh m;
  m.cells = int(std::ceil(std::sqrt(double(ico.triangles.size()))));
  for (std::size_t k = 0; k < ico.triangles.size(); ++k) {
    const auto& t = ico.triangles[k];
    const dvec3 face = glm::normalize(glm::cross(ico.vertices[t[1]] - ico.vertices[t[0]], ico.vertices[t[2]] - ico.vertices[t[0]]));
    const glm::dvec2 cell(double(k % std::size_t(m.cells)), double(k / std::size_t(m.cells)));
    for (std::size_t c = 0; c < 3; ++c) {
      m.positions.push_back(ico.vertices[t[c]]);
      m.normals.push_back(flat ? face : ico.vertices[t[c]]);
      m.texcoords.emplace_back((cell + glm::dvec2(kAtlasCorner[c][0], kAtlasCorner[c][1])) / double(m.cells));
    }
    m.triangles.push_back({std::uint32_t(3 * k), std::uint32_t(3 * k + 1), std::uint32_t(3 * k + 2)});
  }
  return m;
}

}  // namespace matbake::test
