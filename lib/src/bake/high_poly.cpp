#include "high_poly.hpp"

#include <glm/geometric.hpp>
#include <glm/mat2x2.hpp>
#include <tbb/parallel_for.h>

#include <limits>

namespace matbake::bake {

std::unique_ptr<HighPoly> HighPoly::build(const scene::Scene& high, std::shared_ptr<const ao::Bvh> bvh) {
  std::unique_ptr<HighPoly> h(new HighPoly);
  h->scene_ = &high;
  h->bvh_ = std::move(bvh);
  h->normals_.resize(high.instances.size());
  tbb::parallel_for(std::size_t{0}, high.instances.size(), [&](std::size_t k) {
    const scene::Instance& inst = high.instances[k];
    if (!inst.normals.empty()) h->normals_[k] = ao::shading_normals(inst);  // none: glTF's flat normals
  });
  return h;
}

std::optional<Hit> HighPoly::first_hit(const glm::vec3& origin, const glm::vec3& direction, float length, ao::Parts parts,
                                       bool* from_inside) const {
  RTCRayHit rh;
  rh.ray.org_x = origin.x, rh.ray.org_y = origin.y, rh.ray.org_z = origin.z;
  rh.ray.dir_x = direction.x, rh.ray.dir_y = direction.y, rh.ray.dir_z = direction.z;
  rh.ray.tnear = 0, rh.ray.tfar = length, rh.ray.time = 0;
  rh.ray.mask = ~0u, rh.ray.id = 0, rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  ao::RayContext context(false, {}, parts);
  float nearest_back = std::numeric_limits<float>::infinity();
  if (from_inside) context.nearest_back = &nearest_back;
  rtcIntersect1(bvh_->scene(), &context.embree, &rh);
  const bool missed = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID;
  if (from_inside) *from_inside = nearest_back < (missed ? std::numeric_limits<float>::infinity() : rh.ray.tfar);
  if (missed) return std::nullopt;
  Hit hit;
  hit.instance = rh.hit.geomID;  // geometries were attached in instance order, from 0
  hit.triangle = rh.hit.primID;
  hit.distance = rh.ray.tfar;
  hit.weights = glm::vec3(1.0f - rh.hit.u - rh.hit.v, rh.hit.u, rh.hit.v);
  const scene::Instance& inst = scene_->instances[hit.instance];
  const auto& corners = inst.triangles[hit.triangle];
  const auto& normals = normals_[hit.instance];
  glm::vec3 n(0);
  for (std::size_t k = 0; k < 3; ++k) {
    hit.position += hit.weights[int(k)] * inst.positions[corners[k]];
    if (!normals.empty()) n += hit.weights[int(k)] * normals[corners[k]];
  }
  // Opposite vertex normals that cancel: the face's own.
  if (!(glm::length(n) > 0)) n = bvh_->face_normals(hit.instance)[hit.triangle];
  hit.normal = glm::normalize(n);
  return hit;
}

double HighPoly::mean_curvature(const Hit& hit) const {
  const auto& normals = normals_[hit.instance];
  if (normals.empty()) return 0;
  const scene::Instance& inst = scene_->instances[hit.instance];
  const auto& t = inst.triangles[hit.triangle];
  const glm::dvec3 p0(inst.positions[t[0]]), n0(normals[t[0]]);
  const glm::dvec3 e1 = glm::dvec3(inst.positions[t[1]]) - p0, e2 = glm::dvec3(inst.positions[t[2]]) - p0;
  const glm::dvec3 dn1 = glm::dvec3(normals[t[1]]) - n0, dn2 = glm::dvec3(normals[t[2]]) - n0;
  // The shape operator S in the edge basis: S e_i = dn_i, so with the metric G = [e_i · e_j] and
  // M = [e_i · dn_j] (column j), S = G⁻¹ M.
  const glm::dmat2 g(glm::dot(e1, e1), glm::dot(e1, e2), glm::dot(e1, e2), glm::dot(e2, e2));
  const glm::dmat2 m(glm::dot(e1, dn1), glm::dot(e2, dn1), glm::dot(e1, dn2), glm::dot(e2, dn2));
  const double det = glm::determinant(g);
  if (!(det > 1e-12 * g[0][0] * g[1][1])) return 0;  // a degenerate face
  const glm::dmat2 s = glm::inverse(g) * m;
  return 0.5 * (s[0][0] + s[1][1]);
}

}  // namespace matbake::bake
