#include "matbake/workflow_maps.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <span>
#include <cmath>

namespace matbake::workflow {
namespace {

Vec3 colour_at(const image::Image& map, std::size_t i) {
  const float* p = &map.pixels[i * 3];
  return {p[0], p[1], p[2]};
}

void store_colour(image::Image& map, std::size_t i, const Vec3& c) {
  for (int k = 0; k < 3; ++k) map.pixels[i * 3 + std::size_t(k)] = float(c[k]);
}

image::Image like(const image::Image& shape, int channels) {
  image::Image m;
  m.width = shape.width;
  m.height = shape.height;
  m.channels = channels;
  m.channel_names = channels == 3 ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"Y"};
  image::reserve_pixels(m.pixels, m.sample_count());
  m.pixels.assign(m.sample_count(), 0.0f);
  return m;
}

// Mean and arg-max of per-texel errors; NaN entries (texels not measured) are skipped.
ErrorStats statistics(const std::vector<float>& errors, int width) {
  ErrorStats s;
  double sum = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    if (std::isnan(errors[i])) continue;
    sum += errors[i];
    ++s.count;
    if (errors[i] > s.max || s.count == 1) {
      s.max = errors[i];
      s.max_x = int(i % std::size_t(width));
      s.max_y = int(i / std::size_t(width));
    }
  }
  s.mean = s.count ? sum / double(s.count) : 0;
  return s;
}

Result<const image::Image*> need(const material::Maps& in, std::string_view name) {
  const image::Image* map = in.find(name);
  if (!map) return Error{"", "the conversion needs " + std::string(name), true};
  return map;
}

// Every map the conversion does not read (mask, occlusion, normal, emissive, ...) reaches the
// result as it is: a material's maps are the same whichever workflow its layout is in.
// The maps each conversion reads (and the other one writes).
constexpr std::array<std::string_view, 3> kSpecGlossMaps{material::kKd, material::kKs, material::kGloss};
constexpr std::array<std::string_view, 3> kMetalRoughMaps{material::kBaseColor, material::kMetallic, material::kRoughness};

void pass_through(const material::Maps& in, std::span<const std::string_view> converted, material::Maps& out) {
  for (const auto& [name, map] : in.maps) {
    if (std::find(converted.begin(), converted.end(), name) == converted.end()) out.maps.emplace(name, map);
  }
}

// The texels the lobe error is computed on: a regular grid of at most about kLobeTexels.
std::vector<std::size_t> lobe_sample(int width, int height) {
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  const int stride = std::max(1, int(std::ceil(std::sqrt(double(texels) / double(kLobeTexels)))));
  std::vector<std::size_t> sample;
  for (int y = 0; y < height; y += stride) {
    for (int x = 0; x < width; x += stride) sample.push_back(std::size_t(y) * std::size_t(width) + std::size_t(x));
  }
  return sample;
}

// Errors of (kd, ks, gloss) rendered as metal-rough (base, m, r) per texel.
struct Target {
  const image::Image *kd, *ks, *gloss;
};
struct Converted {
  const image::Image *base, *metallic, *roughness;
};

ConversionErrors measure(const Target& t, const Converted& c, const LobeQuadrature& q) {
  const int width = t.kd->width;
  const std::size_t texels = std::size_t(width) * std::size_t(t.kd->height);
  std::vector<float> diffuse(texels), specular(texels), lobe(texels, std::nanf(""));
  tbb::parallel_for(std::size_t(0), texels, [&](std::size_t i) {
    const Vec3 base = colour_at(*c.base, i);
    const double m = c.metallic->pixels[i];
    diffuse[i] = float(delta_e_ab(colour_at(*t.kd, i), diffuse_from_metal_rough(base, m)));
    const Vec3 f0 = specular_from_metal_rough(base, m), ks = colour_at(*t.ks, i);
    specular[i] = float(std::max({std::abs(f0.r - ks.r), std::abs(f0.g - ks.g), std::abs(f0.b - ks.b)}));
  });
  const std::vector<std::size_t> sample = lobe_sample(width, t.kd->height);
  tbb::parallel_for(std::size_t(0), sample.size(), [&](std::size_t k) {
    const std::size_t i = sample[k];
    const Vec3 f0 = specular_from_metal_rough(colour_at(*c.base, i), c.metallic->pixels[i]);
    lobe[i] = float(lobe_error(q, colour_at(*t.ks, i), t.gloss->pixels[i], f0, c.roughness->pixels[i]));
  });
  return {statistics(diffuse, width), statistics(specular, width), statistics(lobe, width)};
}

DielectricF0 dielectric_f0(const image::Image& kd, const image::Image& ks) {
  constexpr double kGrey = 0.02, kMaxF0 = 0.2, kTolerance = 1e-3;
  const std::size_t texels = std::size_t(kd.width) * std::size_t(kd.height);
  std::vector<std::size_t> members;
  double sum = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    const Vec3 s = colour_at(ks, i), d = colour_at(kd, i);
    const double lo = std::min({s.r, s.g, s.b}), hi = std::max({s.r, s.g, s.b});
    if (hi - lo > kGrey || hi > kMaxF0 || std::max({d.r, d.g, d.b}) <= 1e-6) continue;
    const double f0 = (s.r + s.g + s.b) / 3;
    if (std::abs(f0 - kDielectricF0) <= kTolerance) continue;
    members.push_back(i);
    sum += f0;
  }
  DielectricF0 r;
  r.texels = members.size();
  if (members.empty()) return r;
  r.mean_f0 = sum / double(members.size());
  const double root = std::sqrt(r.mean_f0);
  r.ior = (1 + root) / (1 - root);
  r.specular_color_factor = r.mean_f0 / kDielectricF0;
  std::vector<float> without(texels, std::nanf("")), with(texels, std::nanf(""));
  for (std::size_t i : members) {
    const Vec3 s = colour_at(ks, i);
    const double f0 = (s.r + s.g + s.b) / 3;
    without[i] = float(std::abs(f0 - kDielectricF0));
    with[i] = float(std::abs(f0 - r.mean_f0));
  }
  r.error_without_extensions = statistics(without, kd.width);
  r.error_with_extensions = statistics(with, kd.width);
  return r;
}

}  // namespace

Result<material::Maps> metal_rough_from_spec_gloss(const material::Maps& in, RoughnessMapping mapping,
                                                     ConversionReport& report) {
  return guarded("", [&]() -> Result<material::Maps> {
    auto kd = need(in, material::kKd);
    if (!kd) return kd.error();
    auto ks = need(in, material::kKs);
    if (!ks) return ks.error();
    auto gloss = need(in, material::kGloss);
    if (!gloss) return gloss.error();
    material::Maps out;
    out.width = in.width;
    out.height = in.height;
    image::Image base = like(**kd, 3), metallic = like(**gloss, 1), roughness = like(**gloss, 1);
    image::Image khronos_base = base, khronos_metallic = metallic, khronos_roughness = roughness;
    const std::size_t texels = std::size_t(in.width) * std::size_t(in.height);
    tbb::parallel_for(std::size_t(0), texels, [&](std::size_t i) {
      const Vec3 d = colour_at(**kd, i), s = colour_at(**ks, i);
      const BaseMetallic bm = base_metallic_from_spec_gloss(d, s);
      store_colour(base, i, bm.base);
      metallic.pixels[i] = float(bm.metallic);
      roughness.pixels[i] = float(roughness_from_gloss((*gloss)->pixels[i], mapping, mean_f0(s)));
      const BaseMetallic k = khronos_base_metallic(d, s);
      store_colour(khronos_base, i, k.base);
      khronos_metallic.pixels[i] = float(k.metallic);
      khronos_roughness.pixels[i] = 1.0f - (*gloss)->pixels[i];  // the Khronos converter's roughness
    });
    const LobeQuadrature q = make_lobe_quadrature(12);
    const Target target{*kd, *ks, *gloss};
    report.texels = texels;
    report.errors = measure(target, {&base, &metallic, &roughness}, q);
    report.khronos_errors = measure(target, {&khronos_base, &khronos_metallic, &khronos_roughness}, q);
    report.dielectric = dielectric_f0(**kd, **ks);
    out.maps["base_color"] = std::move(base);
    out.maps["metallic"] = std::move(metallic);
    out.maps["roughness"] = std::move(roughness);
    pass_through(in, kSpecGlossMaps, out);
    return out;
  });
}

Result<material::Maps> spec_gloss_from_metal_rough(const material::Maps& in, RoughnessMapping mapping,
                                                     ConversionReport& report) {
  return guarded("", [&]() -> Result<material::Maps> {
    auto base = need(in, material::kBaseColor);
    if (!base) return base.error();
    auto metallic = need(in, material::kMetallic);
    if (!metallic) return metallic.error();
    auto roughness = need(in, material::kRoughness);
    if (!roughness) return roughness.error();
    material::Maps out;
    out.width = in.width;
    out.height = in.height;
    image::Image kd = like(**base, 3), ks = like(**base, 3), gloss = like(**roughness, 1);
    const std::size_t texels = std::size_t(in.width) * std::size_t(in.height);
    tbb::parallel_for(std::size_t(0), texels, [&](std::size_t i) {
      const SpecGloss sg = spec_gloss_from_metal_rough(
          {colour_at(**base, i), (*metallic)->pixels[i], (*roughness)->pixels[i]}, mapping);
      store_colour(kd, i, sg.kd);
      store_colour(ks, i, sg.ks);
      gloss.pixels[i] = float(sg.gloss);
    });
    // The colours are exact (the same relation both ways); the lobe error is the specular shape's.
    report.texels = texels;
    report.errors = measure({&kd, &ks, &gloss}, {*base, *metallic, *roughness}, make_lobe_quadrature(12));
    out.maps["kd"] = std::move(kd);
    out.maps["ks"] = std::move(ks);
    out.maps["gloss"] = std::move(gloss);
    pass_through(in, kMetalRoughMaps, out);
    return out;
  });
}

std::string_view direction_name(Direction d) {
  return d == Direction::metal_rough_from_spec_gloss ? "spec-gloss to metal-rough" : "metal-rough to spec-gloss";
}

std::optional<Direction> layout_direction(const material::MapNames& names, const pack::Layout& layout) {
  const std::vector<std::string> read = pack::layout_sources(layout);
  const auto reads = [&](std::initializer_list<std::string_view> wanted) {
    return std::any_of(wanted.begin(), wanted.end(),
                       [&](std::string_view n) { return std::find(read.begin(), read.end(), n) != read.end(); });
  };
  const auto has_any = [&](std::span<const std::string_view> wanted) {
    return std::any_of(wanted.begin(), wanted.end(), [&](std::string_view n) { return names.contains(n); });
  };
  const bool spec_gloss = has_any(kSpecGlossMaps), metal_rough = has_any(kMetalRoughMaps);
  if (reads({material::kBaseColor, material::kMetallic, material::kRoughness}) && spec_gloss && !metal_rough) {
    return Direction::metal_rough_from_spec_gloss;
  }
  if (reads({material::kKd, material::kKs, material::kGloss}) && metal_rough && !spec_gloss) {
    return Direction::spec_gloss_from_metal_rough;
  }
  return std::nullopt;
}

std::optional<Direction> layout_direction(const material::Maps& maps, const pack::Layout& layout) {
  return layout_direction(maps.names(), layout);
}

material::MapNames names_in_layout_workflow(material::MapNames names, const pack::Layout& layout) {
  const std::optional<Direction> direction = layout_direction(names, layout);
  if (!direction) return names;
  const bool to_metal_rough = *direction == Direction::metal_rough_from_spec_gloss;
  for (std::string_view n : to_metal_rough ? kSpecGlossMaps : kMetalRoughMaps) {
    if (auto it = names.find(n); it != names.end()) names.erase(it);
  }
  for (std::string_view n : to_metal_rough ? kMetalRoughMaps : kSpecGlossMaps) names.emplace(n);
  return names;
}

Result<LayoutMaps> in_layout_workflow(material::Maps maps, const pack::Layout& layout, RoughnessMapping mapping) {
  LayoutMaps out;
  out.direction = layout_direction(maps, layout);
  if (!out.direction) {
    out.maps = std::move(maps);
    return out;
  }
  Result<material::Maps> converted = *out.direction == Direction::metal_rough_from_spec_gloss
                                               ? metal_rough_from_spec_gloss(maps, mapping, out.report)
                                               : spec_gloss_from_metal_rough(maps, mapping, out.report);
  if (!converted) return converted.error();
  out.maps = std::move(*converted);
  return out;
}

}  // namespace matbake::workflow
