// Speed against error of every decode/encode method on one core, on a 2048x2048 RGBA image
// (16.8 M samples), with memcpy of the same output as the ceiling. Each method's error is measured
// against the float64 formula before timing and reported as counters:
//   max_abs / rms_abs: absolute error in linear (decode) or encoded (encode) units;
//   max_ulp: largest distance in floats from float(float64 formula); for integer outputs,
//   wrong_codes: samples whose code differs from rounding the float64 formula.
// Bytes processed = bytes read + bytes written, so GB/s compares directly with memcpy's.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "matbake/color.hpp"
#include "matbake/ocio.hpp"
#include "matbake/pixels.hpp"

namespace {

using matbake::color::Transfer;

constexpr std::size_t kPixels = 2048 * 2048;
constexpr std::size_t kSamples = kPixels * 4;
const std::vector<Transfer> kRgba = {Transfer::srgb, Transfer::srgb, Transfer::srgb, Transfer::linear};

// One core: OCIO applies on one, and per-core speed is what the targets are stated in.
const tbb::global_control kOneThread(tbb::global_control::max_allowed_parallelism, 1);

const std::vector<uint8_t>& codes() {
  static const std::vector<uint8_t> data = [] {
    std::vector<uint8_t> v(kSamples);
    std::mt19937 rng(1);
    for (auto& c : v) c = uint8_t(rng());
    return v;
  }();
  return data;
}

const std::vector<float>& unit_floats() {
  static const std::vector<float> data = [] {
    std::vector<float> v(kSamples);
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (auto& x : v) x = u(rng);
    return v;
  }();
  return data;
}

double reference(Transfer t, bool decode, double x) {
  return decode ? matbake::color::linear_from_encoded(t, x) : matbake::color::encoded_from_linear(t, x);
}

struct ErrorStats {
  double max_abs = 0, sum_sq = 0, max_ulp = 0, wrong = 0;
  std::size_t n = 0;
  void add(double got, double want) {
    const double e = std::abs(got - want);
    max_abs = std::max(max_abs, e);
    sum_sq += e * e;
    const auto ulp = std::abs(int64_t(std::bit_cast<int32_t>(float(got))) - int64_t(std::bit_cast<int32_t>(float(want))));
    max_ulp = std::max(max_ulp, double(ulp));
    ++n;
  }
  void report(benchmark::State& state, bool integer_output) const {
    state.counters["max_abs"] = max_abs;
    state.counters["rms_abs"] = std::sqrt(sum_sq / double(n));
    if (integer_output) state.counters["wrong_codes"] = wrong;
    else state.counters["max_ulp"] = max_ulp;
  }
};

// Error of a float-output kernel over its benchmark input (colour channels and alpha alike).
template <class In>
ErrorStats float_output_error(const std::vector<In>& in, const std::vector<float>& out, bool decode, double scale) {
  ErrorStats s;
  for (std::size_t i = 0; i < in.size(); ++i) s.add(out[i], reference(kRgba[i % 4], decode, double(in[i]) / scale));
  return s;
}

void set_throughput(benchmark::State& state, std::size_t bytes_in, std::size_t bytes_out) {
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(bytes_in + bytes_out));
  state.counters["Mpix/s"] = benchmark::Counter(double(state.iterations()) * double(kPixels) / 1e6,
                                                benchmark::Counter::kIsRate);
}

void BM_memcpy_ceiling(benchmark::State& state) {
  std::vector<float> src(unit_floats()), dst(kSamples);
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), kSamples * sizeof(float));
    benchmark::DoNotOptimize(dst.data());
    benchmark::ClobberMemory();
  }
  set_throughput(state, kSamples * sizeof(float), kSamples * sizeof(float));
}

// --- 8-bit -> float decode -----------------------------------------------------------------

void BM_decode_u8_exact_table(benchmark::State& state) {
  std::vector<float> out(kSamples);
  matbake::color::decode_pixels(std::span<const uint8_t>(codes()), out, kRgba);
  float_output_error(codes(), out, true, 255.0).report(state, false);
  for (auto _ : state) {
    matbake::color::decode_pixels(std::span<const uint8_t>(codes()), out, kRgba);
    benchmark::DoNotOptimize(out.data());
  }
  set_throughput(state, kSamples, kSamples * sizeof(float));
}

// What a straightforward implementation does: the formula in float with std::pow per sample.
float decode_powf(Transfer t, float v) {
  if (t == Transfer::linear) return v;
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

void BM_decode_u8_float_std_pow(benchmark::State& state) {
  std::vector<float> out(kSamples);
  auto run = [&] {
    for (std::size_t i = 0; i < kSamples; ++i) out[i] = decode_powf(kRgba[i % 4], float(codes()[i]) / 255.0f);
  };
  run();
  float_output_error(codes(), out, true, 255.0).report(state, false);
  for (auto _ : state) {
    run();
    benchmark::DoNotOptimize(out.data());
  }
  set_throughput(state, kSamples, kSamples * sizeof(float));
}

void BM_decode_u8_ocio_lut(benchmark::State& state) {
  auto config = matbake::color::OcioConfig::load_builtin();
  auto processor = config->processor("sRGB - Texture", "Linear Rec.709 (sRGB)");
  std::vector<float> out(kSamples);
  processor->apply(std::span<const uint8_t>(codes()), out, 4);
  float_output_error(codes(), out, true, 255.0).report(state, false);
  for (auto _ : state) {
    processor->apply(std::span<const uint8_t>(codes()), out, 4);
    benchmark::DoNotOptimize(out.data());
  }
  set_throughput(state, kSamples, kSamples * sizeof(float));
}

// --- float -> float decode -----------------------------------------------------------------

void BM_decode_float_reference_double_pow(benchmark::State& state) {
  std::vector<float> out(kSamples);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kSamples; ++i) {
      out[i] = float(matbake::color::linear_from_encoded(kRgba[i % 4], unit_floats()[i]));
    }
    benchmark::DoNotOptimize(out.data());
  }
  float_output_error(unit_floats(), out, true, 1.0).report(state, false);
  set_throughput(state, kSamples * sizeof(float), kSamples * sizeof(float));
}

void BM_decode_float_std_pow(benchmark::State& state) {
  std::vector<float> out(kSamples);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kSamples; ++i) out[i] = decode_powf(kRgba[i % 4], unit_floats()[i]);
    benchmark::DoNotOptimize(out.data());
  }
  float_output_error(unit_floats(), out, true, 1.0).report(state, false);
  set_throughput(state, kSamples * sizeof(float), kSamples * sizeof(float));
}

void BM_decode_float_matbake_fast(benchmark::State& state) {
  std::vector<float> out(kSamples);
  for (auto _ : state) {
    matbake::color::decode_pixels(std::span<const float>(unit_floats()), out, kRgba);
    benchmark::DoNotOptimize(out.data());
  }
  float_output_error(unit_floats(), out, true, 1.0).report(state, false);
  set_throughput(state, kSamples * sizeof(float), kSamples * sizeof(float));
}

void BM_decode_float_ocio(benchmark::State& state) {
  auto config = matbake::color::OcioConfig::load_builtin();
  auto processor = config->processor("sRGB - Texture", "Linear Rec.709 (sRGB)");
  std::vector<float> out(kSamples);
  for (auto _ : state) {
    state.PauseTiming();
    out = unit_floats();
    state.ResumeTiming();
    processor->apply(out, 4);
    benchmark::DoNotOptimize(out.data());
  }
  float_output_error(unit_floats(), out, true, 1.0).report(state, false);
  set_throughput(state, kSamples * sizeof(float), kSamples * sizeof(float));
}

// --- float -> 8-bit encode -----------------------------------------------------------------

ErrorStats code_error(const std::vector<float>& in, const std::vector<uint8_t>& out) {
  ErrorStats s;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const Transfer t = kRgba[i % 4];
    s.add(out[i] / 255.0, reference(t, false, in[i]));
    s.wrong += out[i] != matbake::color::quantize_reference(t, 8, in[i]);
  }
  return s;
}

void BM_encode_u8_exact_quantize(benchmark::State& state) {
  std::vector<uint8_t> out(kSamples);
  for (auto _ : state) {
    matbake::color::encode_pixels(unit_floats(), out, kRgba);
    benchmark::DoNotOptimize(out.data());
  }
  code_error(unit_floats(), out).report(state, true);
  set_throughput(state, kSamples * sizeof(float), kSamples);
}

void BM_encode_u8_float_std_pow(benchmark::State& state) {
  std::vector<uint8_t> out(kSamples);
  for (auto _ : state) {
    for (std::size_t i = 0; i < kSamples; ++i) {
      const float l = unit_floats()[i];
      const float e = kRgba[i % 4] == Transfer::linear ? l
                      : l <= 0.0031308f                ? l * 12.92f
                                                       : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
      out[i] = uint8_t(std::lround(std::clamp(e, 0.0f, 1.0f) * 255.0f));
    }
    benchmark::DoNotOptimize(out.data());
  }
  code_error(unit_floats(), out).report(state, true);
  set_throughput(state, kSamples * sizeof(float), kSamples);
}

void BM_encode_float_matbake_fast(benchmark::State& state) {
  std::vector<float> out(kSamples);
  for (auto _ : state) {
    matbake::color::encode_pixels(std::span<const float>(unit_floats()), out, kRgba);
    benchmark::DoNotOptimize(out.data());
  }
  float_output_error(unit_floats(), out, false, 1.0).report(state, false);
  set_throughput(state, kSamples * sizeof(float), kSamples * sizeof(float));
}

}  // namespace

BENCHMARK(BM_memcpy_ceiling)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_u8_exact_table)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_u8_float_std_pow)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_u8_ocio_lut)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_float_reference_double_pow)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_float_std_pow)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_float_matbake_fast)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_decode_float_ocio)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_encode_u8_exact_quantize)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_encode_u8_float_std_pow)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_encode_float_matbake_fast)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
