// The texture bake: coverage (texels.cpp), then the estimator of the per-vertex bake (tracer.cpp) at
// each mapped texel's surface points, then padding.
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "matbake/ao.hpp"
#include "matbake/image.hpp"
#include "texels.hpp"
#include "tracer.hpp"

namespace matbake::ao {
namespace {

using scene::Vec3;
using Clock = std::chrono::steady_clock;

constexpr std::uint64_t kTextureGroup = 1u << 20;  // sample_key groups of textures: beyond any instance index

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The mean of the estimator over the K = texel_samples positions of one surface point's texel
// footprint (stratified by the (0, 2)-sequence, each clamped to the triangle), the rays shared
// among them: position j casts rays j, j + K, ... of the point's sequence.
double point_occlusion(const Tracer& tracer, const scene::Scene& scene, const texels::SurfacePoint& point,
                       const TextureTarget& target, const TextureOptions& texture, int samples, std::uint64_t key,
                       std::span<RTCRayHit> rays, std::uint64_t& cast) {
  const scene::Instance& inst = scene.instances[point.instance];
  const auto& corners = inst.triangles[point.triangle];
  const texels::UvTriangle uv = texels::uv_triangle(inst, target.texcoord, point.triangle, texture.width, texture.height);
  const Mesh& mesh = tracer.mesh(point.instance);
  const Vec3& face = mesh.face_normals[point.triangle];
  const float texel_size = texels::texel_size(double(glm::length(face)), uv);
  const int positions = texture.texel_samples;
  double sum = 0;
  for (int j = 0; j < positions; ++j) {
    glm::dvec2 at(point.x, point.y);
    if (positions > 1) {
      const Sample2 offset = sample(Sampler::sobol, std::uint32_t(j), ~key);
      at += glm::dvec2(offset.u - 0.5, offset.v - 0.5);
    }
    const glm::dvec3 w = texels::nearest_weights(uv, at);
    const Vec3 p = Vec3(w.x * glm::dvec3(inst.positions[corners[0]]) + w.y * glm::dvec3(inst.positions[corners[1]]) +
                        w.z * glm::dvec3(inst.positions[corners[2]]));
    Vec3 n = float(w.x) * mesh.normals[corners[0]] + float(w.y) * mesh.normals[corners[1]] +
             float(w.z) * mesh.normals[corners[2]];
    if (!(glm::length(n) > 0)) n = face;  // opposite vertex normals cancel: the face's own
    n = glm::length(n) > 0 ? glm::normalize(n) : Vec3(0, 0, 1);
    const Vec3 origin = p + n * tracer.origin_offset(p, texel_size);
    sum += tracer.sum_over_rays(origin, n, key, j, positions, rays, cast);
  }
  return sum / samples;
}

}  // namespace

int padding_for(const TextureOptions& options) {
  if (options.padding >= 0) return options.padding;
  const int side = std::max(options.width, options.height);
  return std::max(1, int(std::lround(double(kDefaultPadding) * side / 1024.0)));
}

Status check(const TextureOptions& texture, int max_texel_samples, const std::string& what) {
  if (texture.width < 1 || texture.height < 1 || texture.width > kMaxTextureSide || texture.height > kMaxTextureSide) {
    return Error{"", what + " texture sides must be 1 to " + std::to_string(kMaxTextureSide) + " texels", true};
  }
  if (Status s = image::check_image_size(what + " texture", texture.width, texture.height); !s) return s.error();
  if (texture.padding < -1) return Error{"", what + " padding must be 0 or more texels", true};
  if (texture.texel_samples < 1 || texture.texel_samples > max_texel_samples) {
    return Error{"", what + " texel samples must be 1 to " + std::to_string(max_texel_samples), true};
  }
  return success();
}

Status check(const TextureOptions& texture, const Options& estimator) {
  if (texture.texel_samples > estimator.samples) {
    return Error{"", "AO texel samples must be 1 to the sample count (" + std::to_string(estimator.samples) + ")", true};
  }
  return check(texture, estimator.samples, "AO");
}

Status check(const TextureRequest& request, const Options& estimator) {
  if (Status s = check(request.size, estimator); !s) return s;
  if (request.texcoord < -1) return Error{"", "AO texcoord must be a UV set number (0 or more)", true};
  if (request.bits != 8 && request.bits != 16) return Error{"", "AO texture bits must be 8 or 16", true};
  return success();
}

Result<TextureBakes> bake_textures(const scene::Scene& scene, const Options& options,
                                   const std::vector<TextureTarget>& targets, const TextureOptions& texture,
                                   const StageReport& stage) {
  if (Status s = check(options); !s) return s.error();
  if (Status s = check(texture, options); !s) return s.error();
  for (const TextureTarget& target : targets) {
    if (target.texcoord < 0) return Error{"", "a texture coordinate set is 0 or more", true};
    for (std::size_t k : target.instances) {
      if (k >= scene.instances.size()) return Error{"", "internal: a texture target names an instance that does not exist"};
    }
  }
  const auto start = Clock::now();
  auto built = Tracer::build(scene, options);
  if (!built) return built.error();
  const Tracer& tracer = **built;
  TextureBakes result;
  result.max_distance = tracer.max_distance();
  result.setup_seconds = seconds_since(start);

  const std::size_t texel_count = std::size_t(texture.width) * std::size_t(texture.height);
  const int padding = padding_for(texture);
  for (std::size_t index = 0; index < targets.size(); ++index) {
    const TextureTarget& target = targets[index];
    report_stage(stage, Phase::ao, "AO texture " + std::to_string(index + 1) + " of " + std::to_string(targets.size()) + ", " +
                                       std::to_string(options.samples) + " rays a texel", double(index) / double(targets.size()));
    auto texel_start = Clock::now();
    auto coverage = texels::cover(scene, target, texture.width, texture.height);
    if (!coverage) {
      const std::string name = target.name.empty() ? "texture " + std::to_string(index) : target.name;
      return Error{"", name + ": " + coverage.error().message};
    }
    const std::vector<texels::SurfacePoint>& points = coverage->points;
    std::vector<std::size_t> runs;  // where each mapped texel's points begin, and the end
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (i == 0 || points[i].texel != points[i - 1].texel) runs.push_back(i);
    }
    runs.push_back(points.size());
    result.texel_seconds += seconds_since(texel_start);

    TextureBake& out = result.textures.emplace_back();
    out.width = texture.width, out.height = texture.height;
    out.values.assign(texel_count, 1.0f);
    out.covered = coverage->covered, out.touched = coverage->touched, out.overlapped = coverage->overlapped;
    out.triangles = coverage->triangles, out.degenerate_uv = coverage->degenerate_uv, out.wrapped = coverage->wrapped;
    out.too_large = coverage->too_large;
    out.instances_without_uv = coverage->instances_without_uv;

    texel_start = Clock::now();
    // Texels in 8 × 8 tiles, row by row within a tile: neighbours on the texture (mostly neighbours on
    // the surface) are traced together, so their rays walk the same part of the BVH. Linear time.
    std::vector<std::uint32_t> run_of(texel_count, UINT32_MAX);
    for (std::size_t r = 0; r + 1 < runs.size(); ++r) run_of[points[runs[r]].texel] = std::uint32_t(r);
    std::vector<std::uint32_t> order;
    order.reserve(runs.size() - 1);
    constexpr int kTile = 8;
    for (int ty = 0; ty < texture.height; ty += kTile) {
      for (int tx = 0; tx < texture.width; tx += kTile) {
        for (int y = ty; y < std::min(ty + kTile, texture.height); ++y) {
          for (int x = tx; x < std::min(tx + kTile, texture.width); ++x) {
            const std::uint32_t r = run_of[std::size_t(y) * std::size_t(texture.width) + std::size_t(x)];
            if (r != UINT32_MAX) order.push_back(r);
          }
        }
      }
    }
    result.texel_seconds += seconds_since(texel_start);
    const auto ray_start = Clock::now();
    std::atomic<std::uint64_t> rays{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
      std::vector<RTCRayHit> scratch(std::size_t(options.samples));
      std::uint64_t cast = 0;
      for (std::size_t o = range.begin(); o != range.end(); ++o) {
        const std::size_t r = order[o];
        double sum = 0;
        for (std::size_t i = runs[r]; i < runs[r + 1]; ++i) {
          // Each surface of a texel its own stream: overlapping copies are independent estimates.
          // Keyed apart from the per-vertex bake's streams (instance k, vertex v): texel j × W + i of
          // a texture laid over a grid would otherwise repeat vertex j × W + i's rays exactly.
          const std::uint64_t key = sample_key(options.seed, kTextureGroup + index, points[i].texel) ^
                                    (std::uint64_t(i - runs[r]) << 32);
          sum += point_occlusion(tracer, scene, points[i], target, texture, options.samples, key, scratch, cast);
        }
        out.values[points[runs[r]].texel] = float(sum / double(runs[r + 1] - runs[r]));
      }
      rays += cast;
    });
    out.rays = rays;
    double sum = 0;
    for (std::size_t r = 0; r + 1 < runs.size(); ++r) sum += out.values[points[runs[r]].texel];
    out.mean = runs.size() > 1 ? sum / double(runs.size() - 1) : 0.0;
    result.rays += out.rays;
    result.ray_seconds += seconds_since(ray_start);

    texel_start = Clock::now();
    std::vector<bool> mapped(texel_count, false);
    for (const texels::SurfacePoint& p : points) mapped[p.texel] = true;
    out.padded = texels::pad(out.values, mapped, texture.width, texture.height, padding);
    result.texel_seconds += seconds_since(texel_start);
  }
  return result;
}

}  // namespace matbake::ao
