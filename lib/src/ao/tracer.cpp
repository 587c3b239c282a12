#include "tracer.hpp"

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "sequence.hpp"

namespace matbake::ao {
namespace {

using scene::Vec3;

// An orthonormal basis around n (Duff et al. 2017, branchless).
void basis(const Vec3& n, Vec3& t, Vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = Vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = Vec3(c, sign + n.y * n.y * a, -n.y);
}

}  // namespace

std::vector<Vec3> shading_normals(const scene::Instance& inst, std::optional<scene::NormalWeighting> recompute) {
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

std::vector<float> mean_edge_lengths(const scene::Instance& inst) {
  std::vector<double> sum(inst.positions.size(), 0.0);
  std::vector<int> count(inst.positions.size(), 0);
  for (const auto& t : inst.triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[std::size_t(k)], b = t[std::size_t((k + 1) % 3)];
      const double length = glm::length(inst.positions[a] - inst.positions[b]);
      sum[a] += length, sum[b] += length;
      ++count[a], ++count[b];
    }
  }
  std::vector<float> lengths(inst.positions.size());
  for (std::size_t v = 0; v < sum.size(); ++v) lengths[v] = count[v] ? float(sum[v] / count[v]) : 0.0f;
  return lengths;
}

Result<std::unique_ptr<Tracer>> Tracer::build(const scene::Scene& scene, const Options& options,
                                              std::shared_ptr<const Bvh> bvh) {
  std::unique_ptr<Tracer> tracer(new Tracer);
  tracer->options_ = options;
  if (!bvh) {
    auto built = Bvh::build(scene, options.watertight);
    if (!built) return built.error();
    bvh = std::move(*built);
  }
  tracer->bvh_ = std::move(bvh);
  // Normals and edge lengths per instance, in parallel (the serial part of a short bake otherwise).
  tracer->meshes_.resize(scene.instances.size());
  tbb::parallel_for(std::size_t{0}, scene.instances.size(), [&](std::size_t k) {
    const scene::Instance& inst = scene.instances[k];
    tracer->meshes_[k] = Mesh{shading_normals(inst, options.recompute_normals), mean_edge_lengths(inst)};
  });
  tracer->radius_ = scene.radius();
  tracer->d_max_ = options.absolute_distance > 0 ? options.absolute_distance : options.relative_distance * scene.radius();
  tracer->tau_ = options.tau / tracer->d_max_;
  tracer->normalization_ = 1.0 / (1.0 - std::exp(-tracer->tau_ * tracer->d_max_));
  return tracer;
}

float Tracer::origin_offset(const Vec3& p, float scale) const {
  const float magnitude = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return std::max(std::min(float(options_.bias) * scale, 1e-4f * radius_), 1e-6f * magnitude);
}

unsigned Tracer::aim(const Vec3& origin, const Vec3& n, std::uint64_t key, int first, int step, std::span<RTCRayHit16> rays) const {
  Vec3 t, b;
  basis(n, t, b);
  const float far = float(d_max_);
  const Sequence sequence(options_.sampler, key);
  unsigned count = 0;
  for (int s = first; s < options_.samples; count += 16) {
    RTCRayHit16& packet = rays[count / 16];
    // The packet's samples, then their directions lane by lane with no call or branch (a loop
    // the compiler can turn into vector code).
    float u[16], v[16];
    unsigned lanes = 0;
    for (; lanes < 16 && s < options_.samples; ++lanes, s += step) {
      const Sample2 sample = sequence[std::uint32_t(s)];
      u[lanes] = sample.u, v[lanes] = sample.v;
      packet.ray.id[lanes] = unsigned(s);
    }
    for (unsigned k = lanes; k < 16; ++k) u[k] = v[k] = 0;  // lanes past the end: traced as invalid
    for (unsigned k = 0; k < 16; ++k) {
      // Cosine-weighted: r = √u, φ = 2π v.
      const float r = std::sqrt(u[k]), up = std::sqrt(std::max(0.0f, 1 - u[k]));
      const auto [cos_phi, sin_phi] = unit_circle(v[k]);
      const float x = r * cos_phi, y = r * sin_phi;
      packet.ray.dir_x[k] = t.x * x + b.x * y + n.x * up;
      packet.ray.dir_y[k] = t.y * x + b.y * y + n.y * up;
      packet.ray.dir_z[k] = t.z * x + b.z * y + n.z * up;
      packet.ray.org_x[k] = origin.x, packet.ray.org_y[k] = origin.y, packet.ray.org_z[k] = origin.z;
      packet.ray.tnear[k] = 0, packet.ray.tfar[k] = far, packet.ray.time[k] = 0;
      packet.ray.mask[k] = ~0u, packet.ray.flags[k] = 0;
      packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    }
    if (lanes < 16) return count + lanes;
  }
  return count;
}

void Tracer::trace(unsigned count, std::span<RTCRayHit16> rays, bool occlusion_only, const RayStart& from) const {
  RayContext context(options_.two_sided, from.leaving, from.parts);
  for (unsigned first = 0; first < count; first += 16) {
    alignas(64) int valid[16];
    for (unsigned k = 0; k < 16; ++k) valid[k] = first + k < count ? -1 : 0;
    RTCRayHit16& packet = rays[first / 16];
    if (occlusion_only) {
      rtcOccluded16(valid, bvh_->scene(), &context.embree, &packet.ray);
    } else {
      rtcIntersect16(valid, bvh_->scene(), &context.embree, &packet);
    }
  }
}

namespace {

Vec3 direction(const RTCRay16& rays, unsigned k) { return Vec3(rays.dir_x[k], rays.dir_y[k], rays.dir_z[k]); }

}  // namespace

double Tracer::sum_of_depths(const RayStart& from, std::uint64_t key, int first, int step, std::span<RTCRayHit16> rays,
                             std::uint64_t& cast) const {
  const Vec3& n = from.normal;
  const unsigned count = aim(from.origin, n, key, first, step, rays);
  trace(count, rays, false, from);
  double sum = 0;
  for (unsigned i = 0; i < count; ++i) {
    const RTCRay16& packet = rays[i / 16].ray;  // a miss keeps tfar = d_max
    sum += double(packet.tfar[i % 16]) * double(glm::dot(direction(packet, i % 16), n));
  }
  cast += count;
  return sum;
}

double Tracer::sum_over_rays(const RayStart& from, std::uint64_t key, int first, int step, std::span<RTCRayHit16> rays,
                             std::uint64_t& cast, Vec3* bent) const {
  const unsigned count = aim(from.origin, from.normal, key, first, step, rays);
  const bool binary = options_.falloff == Falloff::none;
  trace(count, rays, binary, from);
  double sum = 0;
  for (unsigned i = 0; i < count; ++i) {
    const RTCRayHit16& packet = rays[i / 16];
    const unsigned k = i % 16;
    double mu = 0;
    if (binary) {
      mu = packet.ray.tfar[k] >= 0 ? 1.0 : 0.0;  // occluded: tfar = −inf
    } else {
      mu = packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID ? 1.0
                                                            : std::min(1.0, (1.0 - std::exp(-tau_ * packet.ray.tfar[k])) * normalization_);
    }
    sum += mu;
    if (bent) *bent += float(mu) * direction(packet.ray, k);
  }
  cast += count;
  return sum;
}

}  // namespace matbake::ao
