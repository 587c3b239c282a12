#include "matbake/ao.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "tracer.hpp"

namespace matbake::ao {

using scene::Vec3;

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
  if (!options.targets.empty() && options.targets.size() != scene.instances.size()) {
    return Error{"", "internal: targets must have one entry per instance"};
  }
  const auto start = std::chrono::steady_clock::now();
  auto tracer = Tracer::build(scene, options);
  if (!tracer) return tracer.error();
  const auto built = std::chrono::steady_clock::now();

  Bake result;
  result.max_distance = (*tracer)->max_distance();
  // Every vertex of every target instance, flattened, so the parallel loop balances across them.
  const auto target = [&](std::size_t k) { return options.targets.empty() || options.targets[k]; };
  std::vector<std::size_t> first(scene.instances.size() + 1, 0);
  result.values.resize(scene.instances.size());
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const std::size_t n = target(k) ? scene.instances[k].positions.size() : 0;
    first[k + 1] = first[k] + n;
    result.values[k].resize(n);
  }

  const Tracer& rays_from = **tracer;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, first.back(), 64), [&](const tbb::blocked_range<std::size_t>& range) {
    RayPackets rays(packets_for(options.samples));
    std::uint64_t cast = 0;
    std::size_t k = std::size_t(std::upper_bound(first.begin(), first.end(), range.begin()) - first.begin()) - 1;
    for (std::size_t flat = range.begin(); flat != range.end(); ++flat) {
      while (flat >= first[k + 1]) ++k;
      const std::size_t v = flat - first[k];
      const Mesh& mesh = rays_from.mesh(k);
      const Vec3 n = mesh.normals[v];
      const Vec3 p = scene.instances[k].positions[v];
      const Vec3 origin = p + n * rays_from.origin_offset(p, mesh.edge_length[v]);
      const double sum = rays_from.sum_over_rays({origin, n, {}}, sample_key(options.seed, k, v), 0, 1, rays, cast);
      result.values[k][v] = float(sum / options.samples);
    }
  });
  result.rays = std::uint64_t(first.back()) * std::uint64_t(options.samples);
  result.setup_seconds = std::chrono::duration<double>(built - start).count();
  result.ray_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
  return result;
}

}  // namespace matbake::ao
