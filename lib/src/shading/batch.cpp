// Schüler's variants in float over arrays. Each lane mirrors schuler.cpp, fresnel.cpp and
// microfacet.cpp with selects instead of branches, so GCC vectorises the loop.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <stdexcept>

#include "float_math.hpp"
#include "matbake/shading_batch.hpp"

namespace matbake::shading {
namespace {

// A call left in the loop stops vectorisation, and GCC -O2 does not inline these on its own.
struct Lane {
  float n_dot_l, n_dot_v, n_dot_h, l_dot_h, ks, gloss;
};

[[gnu::always_inline]] inline float fresnel_schuler_lane(float l_dot_h, float ks) {
  const float m = 1.0f - std::min(std::max(l_dot_h, 0.0f), 1.0f);
  const float m2 = m * m;
  return ks + (std::min(60.0f * ks, 1.0f) - ks) * m2 * m2;
}

// (1 + e)/2 (n·h)^e with e = 2^(12 g).
[[gnu::always_inline]] inline float normalized_blinn_phong_lane(float n_dot_h, float e) {
  return (1.0f + e) * 0.5f * float_math::pow_unit(std::max(n_dot_h, 0.0f), e);
}

// Cook-Torrance's Fresnel for a dielectric with F0 = ks (ks ≥ 1: a mirror, 1).
[[gnu::always_inline]] inline float fresnel_cook_torrance_lane(float c, float ks) {
  c = std::min(std::max(c, 0.0f), 1.0f);
  const float s = std::sqrt(std::min(std::max(ks, 0.0f), 0.999999f));
  const float eta = (1.0f + s) / (1.0f - s);
  const float g = std::sqrt(eta * eta + c * c - 1.0f);  // eta ≥ 1: the argument is ≥ c² ≥ 0
  const float a = (g - c) / std::max(g + c, FLT_MIN);
  const float b = (c * (g + c) - 1.0f) / (c * (g - c) + 1.0f);
  const float f = 0.5f * a * a * (1.0f + b * b);
  return ks >= 1.0f ? 1.0f : f;
}

// π times the normalized Beckmann NDF, m² = 2/(e + 2).
[[gnu::always_inline]] inline float beckmann_pi_d_lane(float n_dot_h, float e) {
  const float m2 = 2.0f / (e + 2.0f);
  // c² ≥ 1e-18 keeps c⁴ a normal float; below it exp(−tan²/m²) is 0 anyway.
  const float c2 = std::min(std::max(n_dot_h * n_dot_h, 1e-18f), 1.0f);
  const float tan2 = (1.0f - c2) / c2;
  const float d = float_math::exp2(-tan2 / m2 * 1.44269504f) / (m2 * c2 * c2);
  return n_dot_h > 0.0f ? d : 0.0f;
}

template <SchulerVariant Variant>
[[gnu::always_inline]] inline float schuler_lane(const Lane& x) {
  const float e = float_math::exp2(12.0f * x.gloss);
  const float l_dot_h = std::max(x.l_dot_h, FLT_MIN);
  float value = 0.0f;
  if constexpr (Variant == SchulerVariant::optimized) {
    value = x.ks * (1.0f + e) * 0.125f * (x.n_dot_l / l_dot_h) / (l_dot_h * l_dot_h) *
            float_math::pow_unit(std::max(x.n_dot_h, 0.0f), e);
  } else if constexpr (Variant == SchulerVariant::kelemen_szirmay_kalos) {
    value = normalized_blinn_phong_lane(x.n_dot_h, e) * fresnel_schuler_lane(x.l_dot_h, x.ks) * 0.25f *
            (x.n_dot_l / l_dot_h) / l_dot_h;
  } else {
    const float k = 2.0f * std::max(x.n_dot_h, 0.0f) / l_dot_h;
    if constexpr (Variant == SchulerVariant::simplified) {
      const float geometric = std::min(k * std::min(x.n_dot_v, x.n_dot_l), 1.0f);
      value = normalized_blinn_phong_lane(x.n_dot_h, e) * fresnel_schuler_lane(x.l_dot_h, x.ks) * geometric /
              (4.0f * x.n_dot_v);
    } else {
      const float geometric = std::min(std::min(k * x.n_dot_v, k * x.n_dot_l), 1.0f);
      value = beckmann_pi_d_lane(x.n_dot_h, e) * fresnel_cook_torrance_lane(x.l_dot_h, x.ks) * geometric /
              (4.0f * x.n_dot_v);
    }
  }
  value = std::min(value, FLT_MAX);
  return x.n_dot_l > 0.0f && x.n_dot_v > 0.0f ? value : 0.0f;
}

template <SchulerVariant Variant>
void schuler_loop(const SchulerBatch& in, std::span<float> out) {
  const float* __restrict n_dot_l = in.n_dot_l.data();
  const float* __restrict n_dot_v = in.n_dot_v.data();
  const float* __restrict n_dot_h = in.n_dot_h.data();
  const float* __restrict l_dot_h = in.l_dot_h.data();
  const float* __restrict ks = in.ks.data();
  const float* __restrict gloss = in.gloss.data();
  float* __restrict result = out.data();
  const std::size_t count = out.size();
  for (std::size_t i = 0; i < count; ++i) {
    result[i] = schuler_lane<Variant>({n_dot_l[i], n_dot_v[i], n_dot_h[i], l_dot_h[i], ks[i], gloss[i]});
  }
}

}  // namespace

void schuler_specular_batch(SchulerVariant variant, const SchulerBatch& in, std::span<float> out) {
  const std::size_t n = out.size();
  for (std::size_t size : {in.n_dot_l.size(), in.n_dot_v.size(), in.n_dot_h.size(), in.l_dot_h.size(),
                           in.ks.size(), in.gloss.size()}) {
    if (size != n) throw std::invalid_argument("schuler_specular_batch: input and output spans differ in size");
  }
  switch (variant) {
    case SchulerVariant::full: return schuler_loop<SchulerVariant::full>(in, out);
    case SchulerVariant::simplified: return schuler_loop<SchulerVariant::simplified>(in, out);
    case SchulerVariant::kelemen_szirmay_kalos: return schuler_loop<SchulerVariant::kelemen_szirmay_kalos>(in, out);
    case SchulerVariant::optimized: return schuler_loop<SchulerVariant::optimized>(in, out);
  }
}

}  // namespace matbake::shading
