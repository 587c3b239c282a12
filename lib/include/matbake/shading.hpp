#pragma once
// Shading models of the reference documents as plain functions of unit vectors and material
// parameters, in float64. No file I/O. Conventions:
// - n, l, v are unit vectors pointing away from the surface (make_geometry renormalizes, so
//   slightly unnormalized input is fine); light or view below the horizon gives 0.
// - Functions named *_brdf return f_r(l, v) in 1/sr, so reflected radiance is
//   f_r · (n·l) · E and Lambert is kd/π.
// - Schüler (GPU Pro 2.5), the chapter-12 Phong form and Strauss write *intensities* with the
//   Lambertian 1/π folded into E (diffuse = kd (n·l) E). Their *_brdf forms divide by π (and by
//   n·l where the intensity carries it), so every model compares with every other.
#include <glm/vec3.hpp>

namespace matbake::shading {

using Vec3 = glm::dvec3;

struct Geometry {
  Vec3 n, l, v, h;  // unit; h = normalize(l + v), or n when l = -v (then l·h = 0)
  double n_dot_l = 0, n_dot_v = 0, n_dot_h = 0;
  double l_dot_h = 0;  // = v·h
  double r_dot_v = 0;  // r: l mirrored about n (Phong)
};
Geometry make_geometry(Vec3 n, Vec3 l, Vec3 v);

// --- Fresnel --------------------------------------------------------------------------------
// Unpolarized dielectric reflectance, (Rs + Rp) / 2, for relative IOR eta = n2 / n1 (eta < 1: from
// the denser side, with total internal reflection giving 1). cos_i in [0, 1].
double fresnel_dielectric(double cos_i, double eta);
// Cook-Torrance's form in c = v·h and g = sqrt(n² + c² − 1) (ch. 12); equal to the above for eta ≥ 1.
double fresnel_cook_torrance(double c, double eta);
// Conductor with complex IOR eta + i·k (exact, unpolarized).
double fresnel_conductor(double cos_i, double eta, double k);
double fresnel_schlick(double cos_i, double f0);
// Schüler: F(t) = lerp(Ks, min(60 Ks, 1), (1 − t)^4).
double fresnel_schuler(double t, double ks);
// Relative IOR of a dielectric with normal reflectance f0: (1 + √f0) / (1 − √f0).
double ior_from_f0(double f0);
// Normal reflectance of a dielectric, ((n − 1)/(n + 1))², and of a conductor, per channel.
double f0_from_ior(double eta, double k = 0);

// --- Microfacet terms -------------------------------------------------------------------------
// Beckmann NDF, normalized so that ∫ D (n·h) dω_h = 1: exp(−tan²θ/m²) / (π m² cos⁴θ). (The slides'
// 1/(4m² cos⁴θ) and the chapter's 1/(m² cos⁴θ) prefactors are not normalized.)
double beckmann_d(double n_dot_h, double m);
// Torrance-Sparrow: min(1, 2 (n·h)(n·v)/(v·h), 2 (n·h)(n·l)/(v·h)).
double torrance_sparrow_g(const Geometry& g);
// Trowbridge-Reitz (GGX) NDF and the height-correlated Smith visibility V = G / (4 (n·l)(n·v)).
double ggx_d(double n_dot_h, double alpha);
double smith_ggx_correlated_v(double n_dot_l, double n_dot_v, double alpha);

// --- Classic lobes (ch. 12): dimensionless terms, as the book's illumination equation uses them --
double phong_lobe(const Geometry& g, double m);        // (r·v)^m
double blinn_phong_lobe(const Geometry& g, double m);  // (n·h)^m
// The chapter-12 illumination equation (12.25) with one light and f(d) = 1:
// I = Ie + Ia ka + Ii (kd (n·l) + ks (n·h)^m).
double phong_illumination(const Geometry& g, double emitted, double ambient, double incident, double ka, double kd,
                          double ks, double m);

// --- BRDFs (1/sr) ------------------------------------------------------------------------------
double lambert_brdf(double kd);
double phong_brdf(const Geometry& g, double ks, double m);        // ks (r·v)^m / (π (n·l))
double blinn_phong_brdf(const Geometry& g, double ks, double m);  // ks (n·h)^m / (π (n·l))
// Two normalizations of Blinn-Phong that are easy to confuse: the slides' (m + 8)/(8π) (n·h)^m
// (Akenine-Möller's approximation of the normalized lobe, no Fresnel, no n·l division), and the
// PBR notes' physically plausible (m + 2)/(8π) F_schlick(l·h) (n·h)^m (a microfacet BRDF with
// D = (m + 2)/(2π) (n·h)^m and G = (n·l)(n·v)). They differ by (m + 8)/(m + 2) → 1 for large m,
// and by the Fresnel factor.
double blinn_phong_normalized_brdf(const Geometry& g, double ks, double m);
double phong_plausible_brdf(const Geometry& g, double f0, double m);
// Cook-Torrance: D F G / (4 (n·l)(n·v)) with Beckmann D (RMS slope m), Torrance-Sparrow G and the
// full dielectric Fresnel of relative IOR eta (Cook-Torrance's c, g form).
double cook_torrance_brdf(const Geometry& g, double eta, double m);
// glTF 2.0's specular BRDF: GGX D, height-correlated Smith, Schlick F; alpha = roughness².
double ggx_brdf(const Geometry& g, double f0, double alpha);
// Oren-Nayar, the simplified form of ch. 12 (first and second order terms), albedo rho, slope σ (rad).
double oren_nayar_brdf(const Geometry& g, double rho, double sigma);

// --- Schüler's model: e = 2^(12 g), and the four variants of his appendix -----------------------
double schuler_exponent(double gloss);  // e = 2^(12 g): 1 to 4096
// The Beckmann RMS slope matched to the exponent (Walter et al. 2007): m = sqrt(2 / (e + 2)).
double beckmann_m_from_exponent(double e);
// Specular intensities per unit light irradiance, as Schüler writes them (they carry n·l):
double schuler_cook_torrance_full(const Geometry& g, double ks, double gloss);  // Beckmann + full Fresnel, TS G
double schuler_cook_torrance_simplified(const Geometry& g, double ks, double gloss);
double schuler_kelemen_szirmay_kalos(const Geometry& g, double ks, double gloss);
double schuler_optimized(const Geometry& g, double ks, double gloss);
enum class SchulerVariant { full, simplified, kelemen_szirmay_kalos, optimized };
double schuler_specular(SchulerVariant variant, const Geometry& g, double ks, double gloss);
double schuler_specular_brdf(SchulerVariant variant, const Geometry& g, double ks, double gloss);

// Schüler's two-hemisphere light (z up): diffuse kd lerp(E_lower, E_upper, (1 + n·z)/2); specular
// F(g n·v) lerp(E_lower, E_upper, clamp(r·z / (1 − g), −1, 1) mapped to [0, 1]) with r the
// reflected view. At g = 1 the clamp becomes a step (sign of r·z).
struct HemisphereLight {
  double lower = 0;
  double upper = 1;
};
double hemisphere_diffuse(const Vec3& n, double kd, const HemisphereLight& light);
double hemisphere_specular(const Vec3& n, const Vec3& v, double ks, double gloss, const HemisphereLight& light);

// --- Strauss (ch. 12; k_f = 1.12, k_g = 1.01, k_j = 0.1): intensity per unit light, one channel --
struct StraussMaterial {
  double color = 0.5;       // c
  double smoothness = 0.5;  // s in [0, 1)
  double metalness = 0;     // m
  double transparency = 0;  // t
};
double strauss_intensity(const Geometry& g, const StraussMaterial& material);  // Q_d + Q_s
double strauss_brdf(const Geometry& g, const StraussMaterial& material);

// Newell's polygon normal (ch. 12), unnormalized: robust for slightly non-planar polygons.
Vec3 newell_normal(const Vec3* vertices, int count);

}  // namespace matbake::shading
