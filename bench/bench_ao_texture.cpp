// Texture-space AO against per-vertex AO at the same ray budget: the generated terrain of bench_ao
// (100 tiles, 62,500 vertices, 115,200 triangles) laid out as a 10 × 10 atlas over one 256²
// texture (65,536 texels, each covered once), binary falloff, d_max 0.25 × the scene radius.
// For 16, 64, 256 and 1024 samples: time, texels (or vertices) per second and rays per second on
// 2 cores and on one, the share of the time spent on texel set-up (UV rasterization, padding), and
// the RMSE against a 4096-sample bake of the same texels (or vertices). Times are medians of at least
// 3 runs and 3 seconds, the two bakes run in turn; set-up shares are summed over the 2-core runs.
//   build/bench/bench_ao_texture            the whole table (about 2 minutes)
//   build/bench/bench_ao_texture --quick    64 samples only
//   build/bench/bench_ao_texture N          N samples only
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string_view>
#include <vector>

#include "matbake/ao.hpp"
#include "terrain.hpp"

using namespace matbake;
using bench::median_seconds;
using bench::seconds_of;

namespace {

double rmse(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += std::pow(double(a[i]) - double(b[i]), 2);
  return std::sqrt(sum / double(a.size()));
}

std::vector<float> flat(const std::vector<std::vector<float>>& values) {
  std::vector<float> out;
  for (const auto& v : values) out.insert(out.end(), v.begin(), v.end());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string_view only = argc > 1 ? argv[1] : "";
  std::vector<int> samples{16, 64, 256, 1024};
  if (only == "--quick") samples = {64};
  else if (!only.empty()) samples = {std::atoi(argv[1])};
  if (samples[0] < 1 || samples[0] > 4096) {
    std::fprintf(stderr, "usage: bench_ao_texture [--quick | SAMPLES (1 to 4096)]\n");
    return 2;
  }
  const scene::Scene s = bench::terrain(true);
  ao::Options options;
  options.falloff = ao::Falloff::none;
  options.two_sided = true;  // as bench_ao: a terrain shows no back faces
  ao::TextureOptions texture;
  texture.width = texture.height = 256;
  texture.padding = 0;
  ao::TextureTarget atlas;
  for (std::size_t k = 0; k < s.instances.size(); ++k) atlas.instances.push_back(k);

  ao::Options reference_options = options;
  reference_options.samples = 4096;
  const std::vector<float> vertex_reference = flat(ao::bake(s, reference_options)->values);
  const ao::TextureBakes texel_reference = *ao::bake_textures(s, reference_options, {atlas}, texture);
  std::printf("binary falloff, %zu vertices, %zu texels (each covered %s), d_max %.3f\n\n", vertex_reference.size(),
              texel_reference.textures[0].covered, texel_reference.textures[0].overlapped ? "more than once" : "once",
              texel_reference.max_distance);
  std::printf("| bake | samples | time, 2 cores | k points/s | M rays/s, 2 cores | M rays/s, 1 core | speed-up | set-up | RMSE vs 4096 |\n"
              "|---|---|---|---|---|---|---|---|---|\n");
  for (int n : samples) {
    ao::Options o = options;
    o.samples = n;
    ao::Bake vertex;
    ao::TextureBakes textured;
    double vertex_setup = 0, vertex_total = 0, setup = 0, texel_setup = 0, total = 0;
    const auto bake_vertices = [&] {
      const double t = seconds_of([&] { vertex = *ao::bake(s, o); });
      vertex_setup += vertex.setup_seconds, vertex_total += t;
    };
    const auto bake_texture = [&] {
      const double t = seconds_of([&] { textured = *ao::bake_textures(s, o, {atlas}, texture); });
      setup += textured.setup_seconds, texel_setup += textured.texel_seconds, total += t;
    };
    const std::vector<double> two = median_seconds({bake_vertices, bake_texture});
    std::vector<double> one;
    {
      tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
      one = median_seconds({[&] { (void)ao::bake(s, o); }, [&] { (void)ao::bake_textures(s, o, {atlas}, texture); }});
    }
    std::printf("| per vertex | %d | %.3f s | %.0f | %.1f | %.1f | %.2f× | %.0f%% | %.5f |\n", n, two[0],
                double(vertex_reference.size()) / two[0] / 1e3, double(vertex.rays) / two[0] / 1e6,
                double(vertex.rays) / one[0] / 1e6, one[0] / two[0], 100 * vertex_setup / vertex_total,
                rmse(flat(vertex.values), vertex_reference));
    const double texels = double(textured.textures[0].covered + textured.textures[0].touched);
    std::printf("| texture 256² | %d | %.3f s | %.0f | %.1f | %.1f | %.2f× | %.0f%% + %.0f%% | %.5f |\n", n, two[1],
                texels / two[1] / 1e3, double(textured.rays) / two[1] / 1e6, double(textured.rays) / one[1] / 1e6,
                one[1] / two[1], 100 * setup / total, 100 * texel_setup / total,
                rmse(textured.textures[0].values, texel_reference.textures[0].values));
  }
  std::printf("\nset-up: Embree's BVH and the normals (both bakes) + texel set-up (texture only), as a share of the time on 2 cores\n");
  return 0;
}
