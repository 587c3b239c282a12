// AO speed against error: a generated terrain of 100 tiles (115,200 triangles), d_max 0.25 × the
// scene radius, binary and exponential falloff. For 16, 64, 256 and 1024 samples: time, rays/s on
// all cores and on one, and the RMSE against a 16384-sample reference on two tiles, for the
// scrambled Sobol sampler and for plain random sampling; then the watertight traversal (the default)
// against Embree's faster non-robust one.
//   build/bench/bench_ao            the whole table (about 4 minutes)
//   build/bench/bench_ao --quick    256 samples, Sobol, both traversals only
#include <tbb/global_control.h>

#include <chrono>
#include <functional>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include "matbake/ao.hpp"
#include "terrain.hpp"

using namespace matbake;
using bench::seconds_of;

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string_view(argv[1]) == "--quick";
  const scene::Scene s = bench::terrain();
  std::size_t triangles = 0;
  for (const auto& i : s.instances) triangles += i.triangles.size();
  std::vector<bool> error_tiles(s.instances.size(), false);
  error_tiles[44] = error_tiles[55] = true;
  for (ao::Falloff falloff : {ao::Falloff::none, ao::Falloff::exponential}) {
    ao::Options reference_options;
    reference_options.falloff = falloff;
    reference_options.two_sided = true;  // as the README's table was measured (a terrain: no back faces seen)
    reference_options.samples = 16384;
    reference_options.targets = error_tiles;
    const ao::Bake reference = *ao::bake(s, reference_options);
    std::printf("\n%s falloff, %zu triangles, d_max %.3f\n\n", falloff == ao::Falloff::none ? "binary" : "exponential",
                triangles, reference.max_distance);
    std::printf("| sampler | samples | edges | time, 2 cores | M rays/s, 2 cores | M rays/s, 1 core | speed-up | RMSE vs 16384 |\n"
                "|---|---|---|---|---|---|---|---|\n");
    struct Row {
      ao::Sampler sampler;
      int samples;
      bool watertight;
    };
    std::vector<Row> rows;
    if (quick) {
      rows = {{ao::Sampler::sobol, 256, true}, {ao::Sampler::sobol, 256, false}};
    } else {
      for (ao::Sampler sampler : {ao::Sampler::sobol, ao::Sampler::random}) {
        for (int samples : {16, 64, 256, 1024}) rows.push_back({sampler, samples, true});
      }
      for (int samples : {64, 256, 1024}) rows.push_back({ao::Sampler::sobol, samples, false});
    }
    for (const Row& row : rows) {
      {
        ao::Options o;
        o.falloff = falloff;
        o.two_sided = true;
        o.samples = row.samples;
        o.sampler = row.sampler;
        o.watertight = row.watertight;
        ao::Bake all;
        const double t2 = seconds_of([&] { all = *ao::bake(s, o); });
        double t1 = 0;
        {
          tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
          t1 = seconds_of([&] { (void)ao::bake(s, o); });
        }
        double sum = 0;
        std::size_t n = 0;
        for (std::size_t k = 0; k < s.instances.size(); ++k) {
          for (std::size_t v = 0; v < reference.values[k].size(); ++v) {
            sum += std::pow(double(all.values[k][v]) - reference.values[k][v], 2);
            ++n;
          }
        }
        std::printf("| %s | %d | %s | %.3f s | %.1f | %.1f | %.2f× | %.5f |\n", row.sampler == ao::Sampler::sobol ? "Sobol" : "random",
                    row.samples, row.watertight ? "watertight" : "fast", t2, double(all.rays) / t2 / 1e6, double(all.rays) / t1 / 1e6, t1 / t2, std::sqrt(sum / double(n)));
      }
    }
  }
  return 0;
}
