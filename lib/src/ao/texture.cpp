// The texture bake: tile by tile, coverage (texels.cpp), then the estimator of the per-vertex bake
// (tracer.cpp) at each mapped texel's surface points; then padding.
#include <glm/geometric.hpp>
#include <tbb/enumerable_thread_specific.h>
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
                       std::span<RTCRayHit16> rays, std::uint64_t& cast) {
  const scene::Instance& inst = scene.instances[point.instance];
  const auto& corners = inst.triangles[point.triangle];
  const texels::UvTriangle uv = texels::uv_triangle(inst, target, point.triangle, texture.width, texture.height);
  const Mesh& mesh = tracer.mesh(point.instance);
  const Vec3& face = tracer.face_normals(point.instance)[point.triangle];
  const float texel_size = texels::texel_size(double(glm::length(face)), uv);
  const int positions = texture.texel_samples;
  const Face leaving{unsigned(point.instance), unsigned(point.triangle)};
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
    sum += tracer.sum_over_rays({origin, n, leaving}, key, j, positions, rays, cast);
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
    const texels::Tiling tiling = texels::tile(scene, target, texture.width, texture.height);
    result.texel_seconds += seconds_since(texel_start);

    TextureBake& out = result.textures.emplace_back();
    out.width = texture.width, out.height = texture.height;
    out.values.assign(texel_count, 1.0f);
    out.triangles = tiling.triangles, out.degenerate_uv = tiling.degenerate_uv, out.wrapped = tiling.wrapped;
    out.too_large = tiling.too_large;
    out.instances_without_uv = tiling.instances_without_uv;
    std::vector<std::uint8_t> mapped(texel_count, 0);
    // Per tile: its coverage, then its texels traced (neighbours on the texture, mostly neighbours
    // on the surface, together: their rays walk the same part of the BVH); its counts kept.
    struct TileTally {
      std::size_t covered = 0, touched = 0, overlapped = 0;
      std::uint64_t rays = 0;
      double sum = 0;
    };
    std::vector<TileTally> tallies(tiling.fragments.size());
    const auto ray_start = Clock::now();
    tbb::enumerable_thread_specific<RayPackets> scratch(packets_for(options.samples));
    const Status covered = texels::cover_tiles(scene, target, tiling, texels::kMaxSurfacePoints, [&](std::size_t t, const texels::TilePoints& tile) {
      TileTally& tally = tallies[t];
      tally.covered = tile.covered, tally.touched = tile.touched, tally.overlapped = tile.overlapped;
      for (std::size_t first = 0, last = 0; first < tile.points.size(); first = last) {
        const std::uint32_t texel = tile.points[first].texel;
        double sum = 0;
        for (last = first; last < tile.points.size() && tile.points[last].texel == texel; ++last) {
          // Each surface of a texel its own stream: overlapping copies are independent estimates.
          // Keyed apart from the per-vertex bake's streams (instance k, vertex v): texel j × W + i of
          // a texture laid over a grid would otherwise repeat vertex j × W + i's rays exactly.
          const std::uint64_t key = sample_key(options.seed, kTextureGroup + index, texel) ^ (std::uint64_t(last - first) << 32);
          sum += point_occlusion(tracer, scene, tile.points[last], target, texture, options.samples, key, scratch.local(), tally.rays);
        }
        out.values[texel] = float(sum / double(last - first));
        tally.sum += out.values[texel];
        mapped[texel] = 1;
      }
    });
    if (!covered) {
      const std::string name = target.name.empty() ? "texture " + std::to_string(index) : target.name;
      return Error{"", name + ": " + covered.error().message};
    }
    double sum = 0;
    for (const TileTally& tally : tallies) {
      out.covered += tally.covered, out.touched += tally.touched, out.overlapped += tally.overlapped;
      out.rays += tally.rays;
      sum += tally.sum;
    }
    const std::size_t texels_mapped = out.covered + out.touched;
    out.mean = texels_mapped ? sum / double(texels_mapped) : 0.0;
    result.rays += out.rays;
    result.ray_seconds += seconds_since(ray_start);  // each tile's coverage with its rays (a few %)

    texel_start = Clock::now();
    out.padded = texels::pad(out.values, std::vector<bool>(mapped.begin(), mapped.end()), texture.width, texture.height, padding);
    result.texel_seconds += seconds_since(texel_start);
  }
  return result;
}

}  // namespace matbake::ao
