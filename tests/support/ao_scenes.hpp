#pragma once
// Scenes for the AO tests, built in memory: squares and the scene around them.
#include <glm/geometric.hpp>

#include <cmath>
#include <vector>

#include "matbake/scene.hpp"

namespace matbake::test {

inline const scene::Vec3 kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

// Three standard deviations of a fraction p estimated from `samples` independent rays (binomial),
// plus a little for the float sums.
inline double three_sigma(double p, int samples) { return 3 * std::sqrt(p * (1 - p) / samples) + 1e-6; }

// A square of half-size `half` in the plane through `center` spanned by u and v, facing u × v, as a
// fan of 4 triangles around its centre vertex (vertex 0). TEXCOORD_0 maps it onto [0, 1]²: u along
// `u`, v along `v`, the centre at (½, ½).
inline scene::Instance square(const scene::Vec3& center, const scene::Vec3& u, const scene::Vec3& v, float half) {
  scene::Instance inst;
  inst.positions = {center, center + half * (-u - v), center + half * (u - v), center + half * (u + v),
                    center + half * (-u + v)};
  inst.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}};
  inst.texcoords = {{{0.5f, 0.5f}, {0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  return inst;
}

inline scene::Scene scene_of(std::vector<scene::Instance> instances) {
  scene::Scene s;
  s.instances = std::move(instances);
  bool first = true;
  for (const scene::Instance& inst : s.instances) {
    for (const scene::Vec3& p : inst.positions) {
      s.bounds_min = first ? p : glm::min(s.bounds_min, p);
      s.bounds_max = first ? p : glm::max(s.bounds_max, p);
      first = false;
    }
  }
  return s;
}

}  // namespace matbake::test
