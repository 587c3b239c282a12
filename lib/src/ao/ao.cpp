#include "matbake/ao.hpp"

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>

namespace matbake::ao {
namespace {

using scene::Vec3;

// --- Sequences -------------------------------------------------------------------------------------
std::uint64_t mix(std::uint64_t x) {  // splitmix64's finalizer: a well-spread 64-bit hash
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

std::uint32_t reverse_bits(std::uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Sobol's second dimension (primitive polynomial x + 1): with the van der Corput first dimension
// a (0, 2)-sequence in base 2.
std::uint32_t sobol_second(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1) {
    if (i & 1) r ^= v;
  }
  return r;
}

constexpr float kTwoToMinus32 = 2.3283064365386963e-10f;

float unit(std::uint32_t bits) { return std::min(float(bits) * kTwoToMinus32, 0x1.fffffep-1f); }

// --- Geometry --------------------------------------------------------------------------------------
// An orthonormal basis around n (Duff et al. 2017, branchless).
void basis(const Vec3& n, Vec3& t, Vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = Vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = Vec3(c, sign + n.y * n.y * a, -n.y);
}

struct Mesh {
  std::vector<Vec3> normals;       // per vertex, unit
  std::vector<float> edge_length;  // per vertex: mean length of its edges (the bias scale)
  std::vector<Vec3> face_normals;  // for one-sided occlusion
};

// The file's unit normals where it has them; else (or when asked) from the faces.
std::vector<Vec3> ray_normals(const scene::Instance& inst, std::optional<scene::NormalWeighting> recompute) {
  const bool usable = !recompute && !inst.normals.empty() &&
                      std::all_of(inst.normals.begin(), inst.normals.end(), [](const Vec3& n) { return glm::length(n) > 0; });
  if (usable) return inst.normals;  // the common case: no face pass at all
  const scene::NormalWeighting weighting = recompute.value_or(scene::NormalWeighting::area);
  std::vector<Vec3> normals = scene::vertex_normals(inst.positions, inst.triangles, weighting, inst.normals).normals;
  if (!recompute && !inst.normals.empty()) {
    for (std::size_t v = 0; v < normals.size(); ++v) {
      if (glm::length(inst.normals[v]) > 0) normals[v] = inst.normals[v];
    }
  }
  return normals;
}

Mesh prepare(const scene::Instance& inst, std::optional<scene::NormalWeighting> recompute) {
  Mesh m;
  m.normals = ray_normals(inst, recompute);
  std::vector<double> sum(inst.positions.size(), 0.0);
  std::vector<int> count(inst.positions.size(), 0);
  for (const auto& t : inst.triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
      const double length = glm::length(inst.positions[a] - inst.positions[b]);
      sum[a] += length, sum[b] += length;
      ++count[a], ++count[b];
    }
    const Vec3 n = glm::cross(inst.positions[t[1]] - inst.positions[t[0]], inst.positions[t[2]] - inst.positions[t[0]]);
    m.face_normals.push_back(n);
  }
  m.edge_length.resize(inst.positions.size());
  for (std::size_t v = 0; v < sum.size(); ++v) m.edge_length[v] = count[v] ? float(sum[v] / count[v]) : 0.0f;
  return m;
}

// One-sided occlusion: a hit on the back of a face (its normal along the ray) is not a hit.
void reject_back_faces(const RTCFilterFunctionNArguments* args) {
  const auto* faces = static_cast<const std::vector<Vec3>*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const Vec3& n = (*faces)[RTCHitN_primID(args->hit, args->N, i)];
    const Vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                 RTCRayN_dir_z(args->ray, args->N, i));
    if (glm::dot(n, d) > 0) args->valid[i] = 0;
  }
}

// The ray-origin offset along the normal: bias × the vertex's mean edge length (local geometry),
// capped at 1e-4 of the scene radius (a huge triangle must not lift the origin through nearby
// geometry) and at least 1e-6 of the vertex's coordinates' magnitude (float precision there: below
// it a ray can hit the surface it leaves). Not of the scene's size: a 1e-4 mesh in a 1e4 scene
// would have its rays start outside it.
float origin_offset(const Vec3& p, float edge_length, float radius, double bias) {
  const float magnitude = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return std::max(std::min(float(bias) * edge_length, 1e-4f * radius), 1e-6f * magnitude);
}

struct DeviceDeleter {
  void operator()(RTCDevice d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCScene s) const { rtcReleaseScene(s); }
};
using Device = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using RtcScene = std::unique_ptr<RTCSceneTy, SceneDeleter>;

}  // namespace

Sample2 sample(Sampler sampler, std::uint32_t i, std::uint64_t key) {
  if (sampler == Sampler::sobol) {
    const std::uint64_t scramble = mix(key);
    return {unit(reverse_bits(i) ^ std::uint32_t(scramble)), unit(sobol_second(i) ^ std::uint32_t(scramble >> 32))};
  }
  const std::uint64_t bits = mix(key ^ mix(i));
  return {unit(std::uint32_t(bits)), unit(std::uint32_t(bits >> 32))};
}

Status check(const Options& options) {
  if (options.samples < 1 || options.samples > kMaxSamples) {
    return Error{"", "AO samples must be 1 to " + std::to_string(kMaxSamples), true};
  }
  if (!(options.relative_distance > 0) || !std::isfinite(options.relative_distance) ||
      !(options.absolute_distance >= 0) || !std::isfinite(options.absolute_distance)) {
    return Error{"", "AO distances must be finite and positive", true};
  }
  if (!(options.tau > 0) || !std::isfinite(options.tau)) return Error{"", "AO tau must be finite and positive", true};
  if (!(options.bias >= 0) || !std::isfinite(options.bias)) return Error{"", "AO bias must be finite and not negative", true};
  return success();
}

std::string_view into_attribute_name(Into into) { return into == Into::attribute ? "_AO" : "COLOR_0"; }
std::string_view into_existing_colors_name(Into into) { return into == Into::color ? "replace" : "multiply"; }
std::optional<Into> into_from_names(std::string_view attribute, std::string_view existing_colors) {
  if (existing_colors != "multiply" && existing_colors != "replace") return std::nullopt;
  if (attribute == "_AO") return Into::attribute;
  if (attribute == "COLOR_0") return existing_colors == "multiply" ? Into::color_multiply : Into::color;
  return std::nullopt;
}

Result<Bake> bake(const scene::Scene& scene, const Options& options) {
  if (Status s = check(options); !s) return s.error();
  const auto start = std::chrono::steady_clock::now();
  Device device(rtcNewDevice(nullptr));
  if (!device) return Error{"", "Embree could not start (rtcNewDevice failed)"};
  RtcScene rtc(rtcNewScene(device.get()));
  if (options.watertight) rtcSetSceneFlags(rtc.get(), RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(rtc.get(), RTC_BUILD_QUALITY_HIGH);
  std::vector<Mesh> meshes;
  meshes.reserve(scene.instances.size());
  for (const scene::Instance& inst : scene.instances) {
    meshes.push_back(prepare(inst, options.recompute_normals));
    RTCGeometry g = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree reads vertex buffers in 16-byte loads: rtcSetNewGeometryBuffer pads for us.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                  3 * sizeof(float), inst.positions.size()));
    for (std::size_t v = 0; v < inst.positions.size(); ++v) {
      vertices[3 * v] = inst.positions[v].x, vertices[3 * v + 1] = inst.positions[v].y, vertices[3 * v + 2] = inst.positions[v].z;
    }
    auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                         3 * sizeof(std::uint32_t), inst.triangles.size()));
    for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) indices[3 * t + std::size_t(k)] = inst.triangles[t][std::size_t(k)];
    }
    if (!options.two_sided) {
      rtcSetGeometryUserData(g, &meshes.back().face_normals);
      rtcSetGeometryIntersectFilterFunction(g, reject_back_faces);
      rtcSetGeometryOccludedFilterFunction(g, reject_back_faces);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(rtc.get(), g);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(rtc.get());
  const auto built = std::chrono::steady_clock::now();
  if (rtcGetDeviceError(device.get()) != RTC_ERROR_NONE) return Error{"", "Embree could not build the scene"};

  Bake result;
  const double d_max = options.absolute_distance > 0 ? options.absolute_distance
                                                     : options.relative_distance * scene.radius();
  result.max_distance = d_max;
  const float far = float(d_max);
  const double tau = options.tau / d_max;
  const double normalization = 1.0 / (1.0 - std::exp(-tau * d_max));
  const bool binary = options.falloff == Falloff::none;
  const float radius = scene.radius();

  if (!options.targets.empty() && options.targets.size() != scene.instances.size()) {
    return Error{"", "internal: targets must have one entry per instance"};
  }
  // Every vertex of every target instance, flattened, so the parallel loop balances across them.
  const auto target = [&](std::size_t k) { return options.targets.empty() || options.targets[k]; };
  std::vector<std::size_t> first(scene.instances.size() + 1, 0);
  result.values.resize(scene.instances.size());
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const std::size_t n = target(k) ? scene.instances[k].positions.size() : 0;
    first[k + 1] = first[k] + n;
    result.values[k].resize(n);
  }

  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, first.back(), 64), [&](const tbb::blocked_range<std::size_t>& range) {
    RTCIntersectContext context;
    // One vertex's rays as a stream: they share an origin, and Embree packs them itself.
    std::vector<RTCRayHit> rays(std::size_t(options.samples));
    std::size_t k = std::size_t(std::upper_bound(first.begin(), first.end(), range.begin()) - first.begin()) - 1;
    for (std::size_t flat = range.begin(); flat != range.end(); ++flat) {
      while (flat >= first[k + 1]) ++k;
      const std::size_t v = flat - first[k];
      const Vec3 n = meshes[k].normals[v];
      const Vec3 p = scene.instances[k].positions[v];
      const Vec3 origin = p + n * origin_offset(p, meshes[k].edge_length[v], radius, options.bias);
      Vec3 t, b;
      basis(n, t, b);
      const std::uint64_t key = options.seed * 0x100000001b3ull ^ (std::uint64_t(k) << 40) ^ v;
      for (int s = 0; s < options.samples; ++s) {
        const Sample2 u = sample(options.sampler, std::uint32_t(s), key);
        // Cosine-weighted: r = √u, φ = 2π v.
        const float r = std::sqrt(u.u), phi = 2 * std::numbers::pi_v<float> * u.v;
        const Vec3 d = t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1 - u.u));
        RTCRayHit& rh = rays[std::size_t(s)];
        rh.ray.org_x = origin.x, rh.ray.org_y = origin.y, rh.ray.org_z = origin.z;
        rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
        rh.ray.tnear = 0, rh.ray.tfar = far, rh.ray.time = 0;
        rh.ray.mask = ~0u, rh.ray.id = unsigned(s), rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      }
      rtcInitIntersectContext(&context);
      double sum = 0;
      if (binary) {
        rtcOccluded1M(rtc.get(), &context, &rays[0].ray, unsigned(options.samples), sizeof(RTCRayHit));
        for (const RTCRayHit& rh : rays) sum += rh.ray.tfar >= 0 ? 1.0 : 0.0;  // occluded rays come back with tfar = −inf
      } else {
        rtcIntersect1M(rtc.get(), &context, rays.data(), unsigned(options.samples), sizeof(RTCRayHit));
        for (const RTCRayHit& rh : rays) {
          sum += rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? 1.0
                                                          : std::min(1.0, (1.0 - std::exp(-tau * rh.ray.tfar)) * normalization);
        }
      }
      result.values[k][v] = float(sum / options.samples);
    }
  });
  result.rays = std::uint64_t(first.back()) * std::uint64_t(options.samples);
  result.setup_seconds = std::chrono::duration<double>(built - start).count();
  result.ray_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
  return result;
}

}  // namespace matbake::ao
