#pragma once
// Per-texel physical checks of a specular map (F0) and, when given, the diffuse colour and the
// mask: the F0 class of every texel (material_table::classify_f0) and what is wrong with it.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/image.hpp"
#include "matbake/material_table.hpp"
#include "matbake/pack.hpp"
#include "matbake/result.hpp"

namespace matbake::validate {

using Vec3 = glm::dvec3;

// What a texel can be flagged for (bits of Texel::flags).
enum Flag : std::uint8_t {
  kBelowReal = 1 << 0,           // F0 < 0.02: no real material reflects this little
  kSemiconductorGap = 1 << 1,    // 0.2 ≤ F0 < 0.45: only semiconductors (silicon) live here
  kMetalWithDiffuse = 1 << 2,    // metal F0 but a diffuse colour (Schüler: metals have none)
  kColouredDielectric = 1 << 3,  // dielectric or gem with a coloured F0 (max − min > 20% of max)
  kAlbedoOutOfRange = 1 << 4,    // a dielectric's or gem's diffuse luminance outside [0.02, 0.94]
  kNotReflectance = 1 << 5,      // an F0 or diffuse channel outside [0, 1]
  kMaterialMismatch = 1 << 6,    // outside the tolerance of the --material entry
};
inline constexpr int kFlagCount = 7;
std::string_view flag_name(int bit);  // "below_real", ...
std::string flag_names(std::uint8_t flags);  // "below_real,metal_with_diffuse"

// The workflow a material was given in, whose words a report uses: the flags are F0 and diffuse
// tests, but an artist with metal-rough maps is told about base colour and metallic.
enum class Vocabulary { spec_gloss, metal_rough };
std::string_view vocabulary_name(Vocabulary vocabulary);  // "spec-gloss", "metal-rough"
// What flag `bit` means in that workflow's terms.
std::string_view flag_meaning(int bit, Vocabulary vocabulary);

// Bounds of a plausible diffuse albedo (luminance, linear): the darkest and brightest opaque
// non-engineered materials of physicallybased.info, charcoal 0.02 and toothpaste 0.935
// (the engineered extremes, Musou Black 0.006 and Spectralon 0.99, are left out).
inline constexpr double kAlbedoMin = 0.02, kAlbedoMax = 0.94;
// Diffuse luminance from which a metal texel counts as having a diffuse colour.
inline constexpr double kMetalDiffuseMax = 0.02;
inline constexpr double kColouredRatio = 0.2;

struct Inputs {
  const image::Image* specular = nullptr;  // linear RGB F0 (required)
  const image::Image* diffuse = nullptr;   // linear RGB (optional)
  const image::Image* mask = nullptr;      // 1 channel (optional): texels with mask ≤ 0 are skipped
};

struct Options {
  const material_table::Material* material = nullptr;  // compare against this entry
  double tolerance = 0.1;                          // relative, per channel: |F0 − ref| ≤ tol · ref
  std::size_t worst_count = 10;
  bool class_map = false;  // keep the per-texel class map (for heatmap())
  double max_violations = 0;  // share of checked texels that may be flagged and still pass
  bool gate = false;  // over max_violations fails (validate exits 3, a build's job fails); else advisory (the default)
};

struct Texel {
  int x = 0, y = 0;
  material_table::F0Class f0_class = material_table::F0Class::dielectric;
  std::uint8_t flags = 0;
  double severity = 0;  // how far outside what is allowed (F0 or luminance units)
  Vec3 f0{0}, diffuse{0};
};

struct ChannelStats {
  double min = 0, max = 0, mean = 0;
};

// Class map entries: the F0 class (0–4), kMaskedTexel, plus kFlaggedTexel when flagged.
inline constexpr std::uint8_t kMaskedTexel = 5, kFlaggedTexel = 0x80;

struct Report {
  int width = 0, height = 0;
  std::size_t texels = 0, masked = 0, checked = 0;
  std::array<std::size_t, 5> class_counts{};  // by material_table::F0Class
  std::array<std::size_t, kFlagCount> flag_counts{};
  std::size_t violations = 0;        // checked texels with any flag
  std::size_t material_within = 0;   // checked texels within the material's tolerance
  std::array<ChannelStats, 3> f0_stats{}, diffuse_stats{};
  std::vector<Texel> worst;          // the most severe, most severe first
  std::vector<std::uint8_t> class_map;
  bool has_diffuse = false;          // a diffuse map was checked too
  Vocabulary vocabulary = Vocabulary::spec_gloss;  // of the maps validate_maps was given
  double violation_fraction() const { return checked ? double(violations) / double(checked) : 0.0; }
};

// Errors: missing specular, channel counts, sizes that differ (naming both sizes).
Result<Report> validate(const Inputs& inputs, const Options& options);

// The class map as an RGB image (linear), one colour per class, flagged texels red; see
// heatmap_legend().
image::Image heatmap(const Report& report);
// heatmap() as an 8-bit sRGB PNG, written atomically.
Status write_heatmap(const Report& report, const std::filesystem::path& png);
// Whether the flagged share is within options.max_violations.
bool passed(const Report& report, const Options& options);
struct LegendEntry {
  std::string_view label;
  std::array<std::uint8_t, 3> srgb;  // 8-bit sRGB as written in the PNG
};
std::span<const LegendEntry> heatmap_legend();

// A material's maps validated: ks (with kd when given) as they are, or F0 and diffuse from base_color
// and metallic (from_metal_rough); the mask when given. Errors say which maps are missing.
Result<Report> validate_maps(const material::Maps& maps, const Options& options);

// F0 and diffuse of metal-rough maps (glTF): F0 = lerp(0.04, base, m), diffuse = base (1 − m).
struct SpecularDiffuse {
  image::Image specular, diffuse;
};
Result<SpecularDiffuse> from_metal_rough(const image::Image& base_color, const image::Image& metallic);

}  // namespace matbake::validate
