#pragma once
// Every BRDF of the shading module behind one signature, for comparisons, benchmarks, previews
// and albedo tables: a material sample (kd, ks, gloss g) is mapped to each model's own parameters.
//   Phong-family exponent: e = 2^(12 g) (Schüler). Beckmann and GGX roughness: m = α =
//   sqrt(2 / (e + 2)) (Walter et al. 2007). Cook-Torrance IOR: from ks as a dielectric's F0.
//   Oren-Nayar: albedo kd, σ = atan(m). Strauss: colour kd, smoothness g, no metalness.
// Diffuse models use kd; specular ones use ks and ignore kd.
#include <span>
#include <string_view>

#include "matbake/shading.hpp"

namespace matbake::shading {

struct MaterialSample {
  double kd = 0.5;
  double ks = 0.04;
  double gloss = 0.5;
};

enum class Lobe { diffuse, specular, both };

struct ModelInfo {
  std::string_view name;
  Lobe lobe;
  std::string_view description;
  bool reciprocal;          // f(l, v) = f(v, l) holds by construction
  bool conserves_energy;    // directional albedo ≤ 1 by construction (for kd, ks ≤ 1)
  double (*brdf)(const Geometry& g, const MaterialSample& m);  // 1/sr
};

std::span<const ModelInfo> models();
const ModelInfo* find_model(std::string_view name);  // nullptr when unknown

// Directional albedo ∫ f(l, v) (n·l) dω_l for a view at polar angle theta_v from n = z, by a
// midpoint rule over the half vector (θ_h = (π/2) t², dense near the lobe; dω_l = 4 (v·h) dω_h).
// error: the difference between `steps` and 2·`steps`, an estimate of the integration error.
struct AlbedoEstimate {
  double value = 0;
  double error = 0;
};
AlbedoEstimate directional_albedo(const ModelInfo& model, const MaterialSample& material, double theta_v,
                                  int steps = 256);

}  // namespace matbake::shading
