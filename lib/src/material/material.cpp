#include "matbake/material.hpp"

#include <algorithm>
#include <array>

namespace matbake::material {
namespace {

constexpr std::array<Source, kSourceCount> kSources = {{
    {kKd, SourceKind::color, "Schüler: diffuse colour"},
    {kKs, SourceKind::color, "Schüler: specular colour, F0"},
    {kMask, SourceKind::scalar, "mask / opacity (alpha of pair A and of base colour maps)"},
    {kGloss, SourceKind::scalar, "Schüler: gloss g, Blinn-Phong exponent 2^(12 g)"},
    {kBaseColor, SourceKind::color, "metalness workflow: base colour"},
    {kMetallic, SourceKind::scalar, "metalness workflow: metallic"},
    {kRoughness, SourceKind::scalar, "metalness workflow: perceptual roughness (GGX alpha = roughness^2)"},
    {kOcclusion, SourceKind::scalar, "ambient occlusion"},
    {kDetailMask, SourceKind::scalar, "Unity HDRP detail mask"},
    {kNormal, SourceKind::vector, "tangent-space normal map (RGB = 0.5 XYZ + 0.5; normal_y says which way green points)"},
    {kEmissive, SourceKind::color, "emitted colour (glTF emissiveTexture)"},
}};

}  // namespace

std::span<const Source> sources() { return kSources; }

const Source* find_source(std::string_view name) {
  for (const Source& s : kSources) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

const image::Image* Maps::find(std::string_view name) const {
  const auto it = maps.find(name);
  return it == maps.end() ? nullptr : &it->second;
}

MapNames Maps::names() const {
  MapNames names;
  for (const auto& entry : maps) names.insert(entry.first);
  return names;
}

bool Maps::has_any(std::initializer_list<std::string_view> names) const {
  return std::any_of(names.begin(), names.end(), [&](std::string_view n) { return find(n) != nullptr; });
}

}  // namespace matbake::material
