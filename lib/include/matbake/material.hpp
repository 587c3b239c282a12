#pragma once
// The in-memory material: named source maps (linear float, colour maps with 3 channels, scalar ones
// with 1, all one size) — what pack, workflow, validate, preview and export hand each other.
#include <map>
#include <set>
#include <span>
#include <string>
#include <string_view>

#include "matbake/image.hpp"

namespace matbake::material {

// The maps' names, as layouts, manifests and the command line (--kd, --base-color, ...) name them.
inline constexpr std::string_view kKd = "kd";                  // Schüler: diffuse colour
inline constexpr std::string_view kKs = "ks";                  // Schüler: specular colour, F0
inline constexpr std::string_view kMask = "mask";              // opacity
inline constexpr std::string_view kGloss = "gloss";            // Schüler: g, e = 2^(12 g)
inline constexpr std::string_view kBaseColor = "base_color";   // metalness workflow
inline constexpr std::string_view kMetallic = "metallic";
inline constexpr std::string_view kRoughness = "roughness";
inline constexpr std::string_view kOcclusion = "occlusion";
inline constexpr std::string_view kDetailMask = "detail_mask";
inline constexpr std::string_view kNormal = "normal";          // tangent space, stored 0.5·n + 0.5, +Y up (glTF's)
inline constexpr std::string_view kEmissive = "emissive";      // emitted colour
inline constexpr std::size_t kSourceCount = 11;

// Colour sources are RGB and authored with a transfer (sRGB or gamma 2.2 in 8/16-bit files);
// scalar sources are one linear channel; vector sources (the normal) are three linear channels.
enum class SourceKind { color, scalar, vector };
struct Source {
  std::string_view name;
  SourceKind kind;
  std::string_view description;
};
std::span<const Source> sources();
const Source* find_source(std::string_view name);
inline int component_count(SourceKind kind) { return kind == SourceKind::scalar ? 1 : 3; }
// A source given as a number holds a texel value: finite and in [0, 1] (NaN fails both).
inline bool is_valid_constant(double value) { return value >= 0.0 && value <= 1.0; }

using MapNames = std::set<std::string, std::less<>>;

struct Maps {
  int width = 0;
  int height = 0;
  std::map<std::string, image::Image, std::less<>> maps;
  const image::Image* find(std::string_view name) const;
  bool has_any(std::initializer_list<std::string_view> names) const;
  MapNames names() const;
  // Which workflow the maps are in: any of kd, ks, gloss / any of base_color, metallic, roughness.
  bool spec_gloss() const { return has_any({kKd, kKs, kGloss}); }
  bool metal_rough() const { return has_any({kBaseColor, kMetallic, kRoughness}); }
};

}  // namespace matbake::material
