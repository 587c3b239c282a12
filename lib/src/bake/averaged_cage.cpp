// The cage of Options::average_normals: the low-poly pushed out along normals averaged where its
// split vertices meet (bake.hpp).
#include <glm/geometric.hpp>

#include <algorithm>
#include <map>
#include <tuple>

#include "../ao/tracer.hpp"
#include "matbake/bake.hpp"

namespace matbake::bake {
namespace {

using scene::Vec3;

// Per vertex, the mean direction of the distinct normals of the vertices at its position: a hard
// edge's two sides meet halfway, a corner of a box points along its diagonal, and vertices split
// only for their UVs (one normal) keep it. Where the distinct normals cancel, the vertex's own.
std::vector<Vec3> averaged_normals(const scene::Instance& inst) {
  const std::vector<Vec3> normals = ao::shading_normals(inst);
  const auto key = [](const Vec3& p) { return std::tuple(p.x, p.y, p.z); };
  std::map<std::tuple<float, float, float>, std::vector<Vec3>> at;  // each position's distinct normals
  for (std::size_t v = 0; v < inst.positions.size(); ++v) {
    std::vector<Vec3>& seen = at[key(inst.positions[v])];
    const auto same = [&](const Vec3& n) { return glm::dot(n, normals[v]) > 1 - 1e-6f; };
    if (std::none_of(seen.begin(), seen.end(), same)) seen.push_back(normals[v]);
  }
  std::vector<Vec3> out(normals.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    Vec3 sum(0);
    for (const Vec3& n : at[key(inst.positions[v])]) sum += n;
    out[v] = glm::length(sum) > 1e-6f ? glm::normalize(sum) : normals[v];
  }
  return out;
}

}  // namespace

scene::Scene averaged_normal_cage(const scene::Scene& low, const std::vector<double>& front) {
  scene::Scene cage;
  cage.instances.resize(low.instances.size());
  for (std::size_t k = 0; k < low.instances.size(); ++k) {
    const scene::Instance& inst = low.instances[k];
    const std::vector<Vec3> normals = averaged_normals(inst);
    std::vector<Vec3>& positions = cage.instances[k].positions;
    for (std::size_t v = 0; v < inst.positions.size(); ++v) positions.push_back(inst.positions[v] + float(front[k]) * normals[v]);
  }
  return cage;
}

}  // namespace matbake::bake
