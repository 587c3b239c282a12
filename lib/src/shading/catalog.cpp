#include <glm/geometric.hpp>

#include <array>
#include <cmath>
#include <numbers>

#include "matbake/shading_catalog.hpp"

namespace matbake::shading {
namespace {

double exponent(const MaterialSample& m) { return schuler_exponent(m.gloss); }
double roughness(const MaterialSample& m) { return beckmann_m_from_exponent(exponent(m)); }

template <SchulerVariant Variant>
double schuler(const Geometry& g, const MaterialSample& m) {
  return schuler_specular_brdf(Variant, g, m.ks, m.gloss);
}

constexpr std::array<ModelInfo, 13> kModels = {{
    {"lambert", Lobe::diffuse, "kd/π", true, true, [](const Geometry&, const MaterialSample& m) { return lambert_brdf(m.kd); }},
    {"phong", Lobe::specular, "ks (r·v)^e / (π n·l), classic", false, false,
     [](const Geometry& g, const MaterialSample& m) { return phong_brdf(g, m.ks, exponent(m)); }},
    {"blinn-phong", Lobe::specular, "ks (n·h)^e / (π n·l), classic", false, false,
     [](const Geometry& g, const MaterialSample& m) { return blinn_phong_brdf(g, m.ks, exponent(m)); }},
    {"blinn-phong-normalized", Lobe::specular, "ks (e+8)/(8π) (n·h)^e (Schmalstieg slides)", true, false,
     [](const Geometry& g, const MaterialSample& m) { return blinn_phong_normalized_brdf(g, m.ks, exponent(m)); }},
    {"phong-plausible", Lobe::specular, "(e+2)/(8π) F_schlick (n·h)^e (PBR notes)", true, true,
     [](const Geometry& g, const MaterialSample& m) { return phong_plausible_brdf(g, m.ks, exponent(m)); }},
    {"cook-torrance", Lobe::specular, "Beckmann D, full Fresnel, Torrance-Sparrow G", true, true,
     [](const Geometry& g, const MaterialSample& m) { return cook_torrance_brdf(g, ior_from_f0(m.ks), roughness(m)); }},
    {"ggx", Lobe::specular, "glTF 2.0: GGX D, height-correlated Smith, Schlick F", true, true,
     [](const Geometry& g, const MaterialSample& m) { return ggx_brdf(g, m.ks, roughness(m)); }},
    {"oren-nayar", Lobe::diffuse, "simplified form of ch. 12", true, false,
     [](const Geometry& g, const MaterialSample& m) { return oren_nayar_brdf(g, m.kd, std::atan(roughness(m))); }},
    {"strauss", Lobe::both, "ch. 12, k_f 1.12, k_g 1.01, k_j 0.1", false, false,
     [](const Geometry& g, const MaterialSample& m) { return strauss_brdf(g, {m.kd, m.gloss, 0.0, 0.0}); }},
    {"schuler-full", Lobe::specular, "CookTorranceFull: Beckmann + full Fresnel", true, true, schuler<SchulerVariant::full>},
    {"schuler-simplified", Lobe::specular, "CookTorranceSimplified", true, false, schuler<SchulerVariant::simplified>},
    {"schuler-ksk", Lobe::specular, "KelemenSzirmayKalos", true, false, schuler<SchulerVariant::kelemen_szirmay_kalos>},
    {"schuler-optimized", Lobe::specular, "Optimized", true, false, schuler<SchulerVariant::optimized>},
}};

}  // namespace

std::span<const ModelInfo> models() { return kModels; }

const ModelInfo* find_model(std::string_view name) {
  for (const ModelInfo& m : kModels) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

namespace {

double albedo_sum(const ModelInfo& model, const MaterialSample& material, const Vec3& v, int steps) {
  const Vec3 n(0, 0, 1);
  const int phi_steps = 2 * steps;
  double sum = 0;
  for (int i = 0; i < steps; ++i) {
    const double t = (i + 0.5) / steps;
    const double theta = std::numbers::pi / 2 * t * t, d_theta = std::numbers::pi * t / steps;
    const double sin_theta = std::sin(theta), cos_theta = std::cos(theta);
    for (int j = 0; j < phi_steps; ++j) {
      const double phi = 2 * std::numbers::pi * (j + 0.5) / phi_steps;
      const Vec3 h(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
      const double v_dot_h = glm::dot(v, h);
      if (v_dot_h <= 0) continue;
      const Vec3 l = 2.0 * v_dot_h * h - v;
      if (l.z <= 0) continue;
      const double f = model.brdf(make_geometry(n, l, v), material);
      sum += f * l.z * 4.0 * v_dot_h * sin_theta * d_theta;
    }
  }
  return sum * 2 * std::numbers::pi / phi_steps;
}

}  // namespace

AlbedoEstimate directional_albedo(const ModelInfo& model, const MaterialSample& material, double theta_v, int steps) {
  const Vec3 v(std::sin(theta_v), 0, std::cos(theta_v));
  const double coarse = albedo_sum(model, material, v, steps);
  const double fine = albedo_sum(model, material, v, 2 * steps);
  return {fine, std::abs(fine - coarse)};
}

}  // namespace matbake::shading
