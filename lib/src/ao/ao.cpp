#include "matbake/ao.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "tracer.hpp"

namespace matbake::ao {
namespace {

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

}  // namespace

using scene::Vec3;

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
    std::vector<RTCRayHit> rays(std::size_t(options.samples));
    std::uint64_t cast = 0;
    std::size_t k = std::size_t(std::upper_bound(first.begin(), first.end(), range.begin()) - first.begin()) - 1;
    for (std::size_t flat = range.begin(); flat != range.end(); ++flat) {
      while (flat >= first[k + 1]) ++k;
      const std::size_t v = flat - first[k];
      const Mesh& mesh = rays_from.mesh(k);
      const Vec3 n = mesh.normals[v];
      const Vec3 p = scene.instances[k].positions[v];
      const Vec3 origin = p + n * rays_from.origin_offset(p, mesh.edge_length[v]);
      const double sum = rays_from.sum_over_rays(origin, n, sample_key(options.seed, k, v), 0, 1, rays, cast);
      result.values[k][v] = float(sum / options.samples);
    }
  });
  result.rays = std::uint64_t(first.back()) * std::uint64_t(options.samples);
  result.setup_seconds = std::chrono::duration<double>(built - start).count();
  result.ray_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - built).count();
  return result;
}

}  // namespace matbake::ao
