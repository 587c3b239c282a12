#pragma once
// The high-poly surface a bake's rays look for: its triangles in Embree (world space), and what a
// hit on them gives — position, interpolated shading normal, which triangle.
#include <embree3/rtcore.h>

#include <glm/vec3.hpp>

#include <memory>
#include <optional>
#include <vector>

#include "../ao/tracer.hpp"
#include "matbake/result.hpp"
#include "matbake/scene.hpp"

namespace matbake::bake {

struct Hit {
  float distance = 0;          // along the ray, from its origin
  glm::vec3 position{0};       // world space
  glm::vec3 normal{0};         // the high-poly's shading normal there, unit: its vertex normals
                               // interpolated, or its face's where it has none (glTF's flat normals)
  std::uint32_t instance = 0, triangle = 0;
  glm::vec3 weights{0};        // barycentric, of the triangle's corners
};

class HighPoly {
 public:
  // `bvh`: the high-poly's, robust (a cage ray must not slip between two triangles).
  static std::unique_ptr<HighPoly> build(const scene::Scene& high, std::shared_ptr<const ao::Bvh> bvh);

  // The first hit on the front of a face (its winding's normal against the ray) of an instance in
  // `parts`, within `length` of `origin` along the unit `direction`. `from_inside`, when given, is
  // set to whether the ray met the back of a face (of those parts) before that hit or without one:
  // it started inside a closed part.
  std::optional<Hit> first_hit(const glm::vec3& origin, const glm::vec3& direction, float length, ao::Parts parts = {},
                               bool* from_inside = nullptr) const;

  // The mean curvature (κ₁ + κ₂)/2 at a hit, from the high-poly's normals: half the trace of the
  // shape operator of its triangle, the derivative of the linearly interpolated vertex normals
  // along the face (constant over it). Positive where the surface is convex (the normals spread), in
  // 1/scene units; exactly 1/r on a sphere of radius r with radial normals, however coarse; 0 on a
  // flat-shaded surface (glTF's flat normals: no curvature within a face).
  double mean_curvature(const Hit& hit) const;

  const scene::Instance& instance(const Hit& hit) const { return scene_->instances[hit.instance]; }

 private:
  HighPoly() = default;
  const scene::Scene* scene_ = nullptr;
  std::shared_ptr<const ao::Bvh> bvh_;
  std::vector<std::vector<glm::vec3>> normals_;  // per instance; none: flat
};

}  // namespace matbake::bake
