// Validation speed: a 4096² specular map (and diffuse and mask), one core (TBB limited to one
// thread), texels per second. Two textures with the same mix (80% dielectrics around F0 0.04 with
// diffuse 0.1–0.7, 15% metals, 5% in the semiconductor gap, 2% masked) and per-texel noise:
//   tiles: one material per 32×32 tile, as in a texture atlas (materials come in regions);
//   noise: the material drawn per texel, the worst case for the branch predictor.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <random>

#include "matbake/validate.hpp"

namespace {

using namespace matbake;

struct Maps {
  image::Image f0, diffuse, mask;
};

Maps make_maps(bool tiles) {
  {
    constexpr int kSize = 4096;
    Maps out;
    for (image::Image* im : {&out.f0, &out.diffuse, &out.mask}) {
      im->width = im->height = kSize;
      im->channels = im == &out.mask ? 1 : 3;
      im->pixels.resize(im->sample_count());
    }
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0, 1);
    for (std::size_t i = 0; i < std::size_t(kSize) * kSize; ++i) {
      const std::size_t x = i % kSize, y = i / kSize;
      // The material pick: per 32×32 tile (a hash of the tile), or per texel.
      const float pick = tiles ? float((((x / 32) * 73856093u) ^ ((y / 32) * 19349663u)) % 1000u) / 1000.0f : u(rng);
      const float f0 = pick < 0.8f ? 0.035f + 0.01f * u(rng) : pick < 0.95f ? 0.6f + 0.35f * u(rng) : 0.3f;
      const float kd = pick < 0.8f ? 0.1f + 0.6f * u(rng) : 0.0f;
      for (std::size_t c = 0; c < 3; ++c) {
        out.f0.pixels[i * 3 + c] = f0;
        out.diffuse.pixels[i * 3 + c] = kd;
      }
      out.mask.pixels[i] = u(rng) < 0.02f ? 0.0f : 1.0f;
    }
    return out;
  }
}

const Maps& maps(bool tiles) {
  static const Maps tiled = make_maps(true), noisy = make_maps(false);
  return tiles ? tiled : noisy;
}

void BM_validate(benchmark::State& state) {
  const Maps& m = maps(state.range(3) != 0);
  tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
  validate::Options options;
  options.class_map = state.range(0) != 0;
  options.material = state.range(1) ? material_table::find(material_table::builtin_table(), "gold") : nullptr;
  const bool whole_pair = state.range(2) != 0;  // else pair B alone: the F0 map
  const validate::Inputs inputs{&m.f0, whole_pair ? &m.diffuse : nullptr, whole_pair ? &m.mask : nullptr};
  for (auto _ : state) {
    auto report = validate::validate(inputs, options);
    benchmark::DoNotOptimize(report);
  }
  state.counters["Mtexel/s"] = benchmark::Counter(double(state.iterations()) * double(m.f0.width) * m.f0.height / 1e6,
                                                  benchmark::Counter::kIsRate);
}
BENCHMARK(BM_validate)
    ->ArgNames({"class_map", "material", "whole_pair", "tiles"})
    ->Args({0, 0, 0, 1})
    ->Args({0, 0, 1, 1})
    ->Args({1, 0, 1, 1})
    ->Args({1, 1, 1, 1})
    ->Args({0, 0, 0, 0})
    ->Args({1, 0, 1, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
