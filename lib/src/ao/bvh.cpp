#include "bvh.hpp"

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace matbake::ao {
namespace {

using scene::Vec3;

// Called for every hit Embree finds: rejects those on the face the rays leave, on an instance
// outside the trace's parts, and on a face's back unless the trace is two-sided (noting the
// nearest such back where asked).
void face_filter(const RTCFilterFunctionNArguments* args) {
  const auto* context = reinterpret_cast<const RayContext*>(args->context);
  const auto* faces = static_cast<const std::vector<Vec3>*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned triangle = RTCHitN_primID(args->hit, args->N, i);
    const unsigned instance = RTCHitN_geomID(args->hit, args->N, i);
    if ((triangle == context->leaving.triangle && instance == context->leaving.instance) ||
        (context->parts.of && (*context->parts.of)[instance] != context->parts.part)) {
      args->valid[i] = 0;
      continue;
    }
    if (context->two_sided) continue;
    const Vec3& n = (*faces)[triangle];
    const Vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                 RTCRayN_dir_z(args->ray, args->N, i));
    if (glm::dot(n, d) <= 0) continue;
    args->valid[i] = 0;
    // Embree holds the candidate's distance in the ray's tfar while it asks.
    if (context->nearest_back) *context->nearest_back = std::min(*context->nearest_back, RTCRayN_tfar(args->ray, args->N, i));
  }
}

// A triangle geometry of the instance's world positions and triangles, not yet committed.
RTCGeometry triangle_geometry(RTCDevice device, const scene::Instance& inst) {
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree reads vertex buffers in 16-byte loads: rtcSetNewGeometryBuffer pads for us.
  auto* vertices = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), inst.positions.size()));
  for (std::size_t v = 0; v < inst.positions.size(); ++v) {
    vertices[3 * v] = inst.positions[v].x, vertices[3 * v + 1] = inst.positions[v].y, vertices[3 * v + 2] = inst.positions[v].z;
  }
  auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                       3 * sizeof(std::uint32_t), inst.triangles.size()));
  for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
    for (std::size_t corner = 0; corner < 3; ++corner) indices[3 * t + corner] = inst.triangles[t][corner];
  }
  return g;
}

}  // namespace

Result<std::shared_ptr<const Bvh>> Bvh::build(const scene::Scene& scene, bool robust) {
  std::shared_ptr<Bvh> bvh(new Bvh);
  bvh->device_.reset(rtcNewDevice(nullptr));
  if (!bvh->device_) return Error{"", "Embree could not start (rtcNewDevice failed)"};
  RTCDevice device = bvh->device_.get();
  bvh->scene_.reset(rtcNewScene(device));
  RTCScene rtc = bvh->scene_.get();
  if (robust) rtcSetSceneFlags(rtc, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(rtc, RTC_BUILD_QUALITY_HIGH);
  bvh->face_normals_.resize(scene.instances.size());
  tbb::parallel_for(std::size_t{0}, scene.instances.size(), [&](std::size_t k) {
    const scene::Instance& inst = scene.instances[k];
    auto& faces = bvh->face_normals_[k];
    faces.reserve(inst.triangles.size());
    for (const auto& t : inst.triangles) {
      faces.push_back(glm::cross(inst.positions[t[1]] - inst.positions[t[0]], inst.positions[t[2]] - inst.positions[t[0]]));
    }
  });
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    RTCGeometry g = triangle_geometry(device, scene.instances[k]);
    rtcSetGeometryUserData(g, &bvh->face_normals_[k]);
    rtcSetGeometryIntersectFilterFunction(g, face_filter);
    rtcSetGeometryOccludedFilterFunction(g, face_filter);
    rtcCommitGeometry(g);
    rtcAttachGeometry(rtc, g);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(rtc);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) return Error{"", "Embree could not build the scene"};
  return std::shared_ptr<const Bvh>(std::move(bvh));
}

}  // namespace matbake::ao
