#include <glm/geometric.hpp>

#include "matbake/shading.hpp"

namespace matbake::shading {

Geometry make_geometry(Vec3 n, Vec3 l, Vec3 v) {
  Geometry g;
  g.n = glm::normalize(n);
  g.l = glm::normalize(l);
  g.v = glm::normalize(v);
  const Vec3 sum = g.l + g.v;
  const double length = glm::length(sum);
  // l = −v has no half vector; every model returns 0 there anyway (one of n·l, n·v is ≤ 0).
  g.h = length > 0 ? sum / length : g.n;
  g.n_dot_l = glm::dot(g.n, g.l);
  g.n_dot_v = glm::dot(g.n, g.v);
  g.n_dot_h = glm::dot(g.n, g.h);
  g.l_dot_h = glm::dot(g.l, g.h);
  g.r_dot_v = glm::dot(2.0 * g.n_dot_l * g.n - g.l, g.v);
  return g;
}

Vec3 newell_normal(const Vec3* vertices, int count) {
  Vec3 normal(0.0);
  for (int i = 0; i < count; ++i) {
    const Vec3& a = vertices[i];
    const Vec3& b = vertices[(i + 1) % count];
    normal.x += (a.y - b.y) * (a.z + b.z);
    normal.y += (a.z - b.z) * (a.x + b.x);
    normal.z += (a.x - b.x) * (a.y + b.y);
  }
  return normal;
}

}  // namespace matbake::shading
