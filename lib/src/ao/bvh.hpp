#pragma once
// A scene's triangles in one Embree BVH, shared by everything that traces that scene: a bake's cage
// rays, its occlusion rays and its thickness rays use one build, not three (a second build was a
// sixth of a 16-ray AO bake on a 20k-triangle high-poly). Whether the back of a face is a hit is
// each trace's choice (RayContext), not the BVH's.
#include <embree3/rtcore.h>

#include <memory>
#include <vector>

#include "matbake/result.hpp"
#include "matbake/scene.hpp"

namespace matbake::ao {

struct DeviceDeleter {
  void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCScene s) const { rtcReleaseScene(s); }
};

class Bvh {
 public:
  // The scene's instances in order (Embree's geometry k is instance k), world space. `robust`:
  // Embree's robust traversal, where no ray slips between two triangles sharing an edge.
  // Errors: Embree failing to start or build.
  static Result<std::shared_ptr<const Bvh>> build(const scene::Scene& scene, bool robust);

  RTCScene scene() const { return scene_.get(); }
  // Instance k's face normals, not normalized (|n| = twice the area): they decide a face's back.
  const std::vector<scene::Vec3>& face_normals(std::size_t instance) const { return face_normals_[instance]; }

 private:
  Bvh() = default;
  std::unique_ptr<RTCDeviceTy, DeviceDeleter> device_;
  std::unique_ptr<RTCSceneTy, SceneDeleter> scene_;
  std::vector<std::vector<scene::Vec3>> face_normals_;  // sized once: the filter keeps pointers into it
};

// A triangle of a Bvh: instance (Embree's geometry) and triangle index; none by default.
struct Face {
  unsigned instance = RTC_INVALID_GEOMETRY_ID, triangle = RTC_INVALID_GEOMETRY_ID;
};

// Which instances of a Bvh a trace may hit: every one (no `of`), or those whose part number
// (`of`, one per instance) is `part` (a bake's parts matched by name).
struct Parts {
  const std::vector<std::uint32_t>* of = nullptr;
  std::uint32_t part = 0;
};

// The context every trace of a Bvh passes Embree, which hands it to the BVH's filter: a hit on the
// back of a face (its normal along the ray) is no hit unless `two_sided`, the face the rays leave is
// never one, nor is a face of an instance outside `parts`. Rays from a point of a face go around its
// shading normal, whose hemisphere near an edge of a curved mesh reaches below the face's plane:
// such a ray would meet the face it leaves (Cycles skips that face too).
struct RayContext {
  RTCIntersectContext embree;  // first, so that Embree's pointer to it is a pointer to this
  bool two_sided = false;
  Face leaving;
  Parts parts;
  // When set (rtcIntersect1 only), the distance of the nearest back face the trace passed: a ray
  // whose first surface is a face's back started inside a closed part.
  float* nearest_back = nullptr;
  RayContext(bool two_sided_traces, Face leaving_face, Parts seen = {})
      : two_sided(two_sided_traces), leaving(leaving_face), parts(seen) {
    rtcInitIntersectContext(&embree);
  }
};

}  // namespace matbake::ao
