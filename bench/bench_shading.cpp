// Speed against error of the shading models. Time: ns per BRDF evaluation over 1M random
// (l, v, material) samples, geometry precomputed (make_geometry is timed on its own). Error of
// Schüler's simplifications and normalized Blinn-Phong against CookTorranceFull: on n·l-weighted
// radiance f·(n·l) (unit irradiance) over the lobe, i.e. with l drawn around the reflection by
// sampling the half vector from Full's Beckmann NDF; counters rms/max absolute, and rms_rel
// (RMS error / RMS of Full's radiance).
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "matbake/shading_batch.hpp"
#include "matbake/shading_catalog.hpp"

namespace {

using namespace matbake::shading;
constexpr std::size_t kSamples = 1 << 20;

struct Sample {
  Geometry geometry;
  MaterialSample material;
};

Vec3 direction(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

// l and v uniform over the upper hemisphere, materials uniform (ks in [0.02, 1], g in [0, 1]).
const std::vector<Sample>& random_samples() {
  static const std::vector<Sample> samples = [] {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Sample> s(kSamples);
    for (auto& x : s) {
      x.geometry = make_geometry({0, 0, 1}, direction(u(rng), 2 * std::numbers::pi * u(rng)),
                                 direction(u(rng), 2 * std::numbers::pi * u(rng)));
      x.material = {u(rng), 0.02 + 0.98 * u(rng), u(rng)};
    }
    return s;
  }();
  return samples;
}

// Samples on the lobe: h from the Beckmann NDF of Full (tan²θ_h = −m² ln(1 − u)), l mirrored.
const std::vector<Sample>& lobe_samples() {
  static const std::vector<Sample> samples = [] {
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Sample> s;
    s.reserve(kSamples);
    while (s.size() < kSamples) {
      const MaterialSample material{0.5, 0.02 + 0.98 * u(rng), u(rng)};
      const double m = beckmann_m_from_exponent(schuler_exponent(material.gloss));
      const double tan2 = -m * m * std::log(1 - u(rng));
      const Vec3 h = direction(1 / std::sqrt(1 + tan2), 2 * std::numbers::pi * u(rng));
      const Vec3 v = direction(u(rng), 2 * std::numbers::pi * u(rng));
      const Vec3 l = 2.0 * (v.x * h.x + v.y * h.y + v.z * h.z) * h - v;
      if (l.z <= 0) continue;
      s.push_back({make_geometry({0, 0, 1}, l, v), material});
    }
    return s;
  }();
  return samples;
}

void BM_make_geometry(benchmark::State& state) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> dirs(4096);
  for (auto& d : dirs) d = {u(rng), u(rng), std::abs(u(rng)) + 0.1};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(make_geometry({0, 0, 1}, dirs[i & 4095], dirs[(i + 7) & 4095]));
    ++i;
  }
  state.counters["ns/eval"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate |
                                                                               benchmark::Counter::kInvert);
}

void BM_model(benchmark::State& state, const ModelInfo* model) {
  const auto& samples = random_samples();
  for (auto _ : state) {
    double sum = 0;
    for (const Sample& s : samples) sum += model->brdf(s.geometry, s.material);
    benchmark::DoNotOptimize(sum);
  }
  state.counters["ns/eval"] = benchmark::Counter(double(state.iterations()) * kSamples,
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  // Error against Full on the lobe, for the models that approximate it.
  const ModelInfo* full = find_model("schuler-full");
  const std::string_view name = model->name;
  if (name != "schuler-simplified" && name != "schuler-ksk" && name != "schuler-optimized" &&
      name != "blinn-phong-normalized") {
    return;
  }
  // Also away from grazing (n·l and n·v ≥ 0.2), where Full's 1/(n·v) and Optimized's 1/(l·h)³ growth
  // do not dominate.
  double sum_sq = 0, max_abs = 0, full_sq = 0, away_sq = 0, away_full_sq = 0;
  for (const Sample& s : lobe_samples()) {
    const double n_dot_l = s.geometry.n_dot_l;
    const double reference = full->brdf(s.geometry, s.material) * n_dot_l;
    const double e = std::abs(model->brdf(s.geometry, s.material) * n_dot_l - reference);
    sum_sq += e * e;
    full_sq += reference * reference;
    max_abs = std::max(max_abs, e);
    if (n_dot_l >= 0.2 && s.geometry.n_dot_v >= 0.2) {
      away_sq += e * e;
      away_full_sq += reference * reference;
    }
  }
  state.counters["rms_vs_full"] = std::sqrt(sum_sq / kSamples);
  state.counters["max_vs_full"] = max_abs;
  state.counters["rms_rel"] = std::sqrt(sum_sq / full_sq);
  state.counters["rms_rel_away"] = std::sqrt(away_sq / away_full_sq);
}

// The random samples as float arrays, and the float64 functions' values on exactly those inputs.
struct FloatSamples {
  std::vector<float> n_dot_l, n_dot_v, n_dot_h, l_dot_h, ks, gloss;
  SchulerBatch batch() const { return {n_dot_l, n_dot_v, n_dot_h, l_dot_h, ks, gloss}; }
};

const FloatSamples& float_samples() {
  static const FloatSamples samples = [] {
    FloatSamples f;
    for (const Sample& s : random_samples()) {
      f.n_dot_l.push_back(float(s.geometry.n_dot_l));
      f.n_dot_v.push_back(float(s.geometry.n_dot_v));
      f.n_dot_h.push_back(float(s.geometry.n_dot_h));
      f.l_dot_h.push_back(float(s.geometry.l_dot_h));
      f.ks.push_back(float(s.material.ks));
      f.gloss.push_back(float(s.material.gloss));
    }
    return f;
  }();
  return samples;
}

// Batched float path: ns per evaluation, and its largest relative error against the float64
// function evaluated on the same (float-rounded) dot products and material.
void BM_batch(benchmark::State& state, SchulerVariant variant) {
  const FloatSamples& in = float_samples();
  std::vector<float> out(in.ks.size());
  for (auto _ : state) {
    schuler_specular_batch(variant, in.batch(), out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns/eval"] = benchmark::Counter(double(state.iterations()) * double(out.size()),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  double max_rel = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    Geometry g;
    g.n_dot_l = in.n_dot_l[i];
    g.n_dot_v = in.n_dot_v[i];
    g.n_dot_h = in.n_dot_h[i];
    g.l_dot_h = in.l_dot_h[i];
    const double reference = schuler_specular(variant, g, in.ks[i], in.gloss[i]);
    // Below 1e-6 (darker than any 16-bit output shows) pow's exponent, up to −126, amplifies float
    // rounding: up to 4e-5 relative there.
    if (reference >= 1e-6) max_rel = std::max(max_rel, std::abs(out[i] - reference) / reference);
  }
  state.counters["max_rel_vs_f64"] = max_rel;
}

const bool kRegistered = [] {
  for (const ModelInfo& m : models()) {
    benchmark::RegisterBenchmark(("BM_" + std::string(m.name)).c_str(), BM_model, &m)->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("BM_batch_schuler-full", BM_batch, SchulerVariant::full)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_batch_schuler-simplified", BM_batch, SchulerVariant::simplified)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_batch_schuler-ksk", BM_batch, SchulerVariant::kelemen_szirmay_kalos)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_batch_schuler-optimized", BM_batch, SchulerVariant::optimized)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_make_geometry", BM_make_geometry);
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
