#include "ao_options.hpp"

#include "option_names.hpp"

#include <cstdio>

namespace matbake::cli {

void add_ao_options(CLI::App& cmd, AoSettings& s, const std::string& prefix, bool textures) {
  ao::Options& o = s.request.options;
  const std::string p = "--" + prefix;
  const std::string group = prefix.empty() ? "Options" : "Ambient occlusion";
  cmd.add_option(p + "samples", o.samples, textures ? "Rays per vertex, or per texel with --texture" : "Rays per vertex")->capture_default_str()->group(group);
  cmd.add_option(p + "relative-distance", o.relative_distance, "d_max as a fraction of the scene radius")
      ->capture_default_str()->group(group);
  cmd.add_option(p + "max-distance", o.absolute_distance, "d_max in scene units (instead of the relative distance)")
      ->group(group);
  cmd.add_option(p + "tau", o.tau, "Falloff rate τ in units of 1/d_max")->capture_default_str()->group(group);
  add_name_option(cmd, p + "falloff", o.falloff, ao::kFalloffNames,
                  "μ(x) (exponential: 1 − e^(−τx), normalized to 1 at d_max; none: binary AO)")
      ->group(group);
  cmd.add_option(p + "bias", o.bias, "Ray-origin offset along the normal × the vertex's mean edge length")
      ->capture_default_str()->group(group);
  cmd.add_flag(p + "two-sided", o.two_sided, "Surfaces seen from behind occlude too (default: only their fronts)")
      ->group(group);
  cmd.add_flag_callback(p + "fast-traversal", [&o] { o.watertight = false; },
                        "Embree's non-robust traversal: faster, but a ray may slip between triangles sharing an edge")
      ->group(group);
  cmd.add_option(p + "seed", o.seed, "Sample scrambling seed (same seed, same values, any --jobs)")
      ->capture_default_str()->group(group);
  add_name_option(cmd, p + "sampler", o.sampler, ao::kSamplerNames, "Directions")->group(group);
  cmd.add_option_function<std::string>(
         p + "recompute-normals",
         [&o, p](const std::string& text) {
           o.recompute_normals = scene::normal_weighting_from_name(text);
           if (!o.recompute_normals) {
             throw CLI::ValidationError(p + "recompute-normals", "'" + text + "': use " + names_in(scene::kNormalWeightingNames));
           }
         },
         "Replace the file's normals, weighting faces by: " + names_in(scene::kNormalWeightingNames))
      ->group(group);
  cmd.add_option(p + "into", s.into, "COLOR_0 (multiplies the base colour in any viewer) or _AO (a float attribute)")
      ->capture_default_str()->group(group);
  cmd.add_option(p + "existing-colors", s.existing_colors,
                 "With COLOR_0, a primitive's own COLOR_0: multiply (kept, times AO; alpha kept) or replace")
      ->capture_default_str()->group(group);
  if (!textures) return;
  const std::string texture_group = "Texture bake (occlusionTexture)";
  ao::TextureRequest& t = s.texture_request;
  cmd.add_option(p + "texture", s.texture,
                 "Bake one occlusion texture of this size (1024, or WxH) per material the scene reaches, over its UVs,\n"
                 "instead of per-vertex values")
      ->group(texture_group);
  cmd.add_option(p + "texcoord", t.texcoord, "UV set (default: the material's occlusionTexture texCoord, else 0)")
      ->group(texture_group);
  cmd.add_option(p + "bits", t.bits, "Linear PNG bits: 8 or 16")->capture_default_str()->group(texture_group);
  cmd.add_option(p + "padding", t.size.padding,
                 "Texels around the UV islands that take the nearest island texel's value (default: 16 at 1024, scaled)")
      ->group(texture_group);
  cmd.add_option(p + "texel-samples", t.size.texel_samples,
                 "Surface points per texel, stratified over its footprint (anti-aliasing); the rays are shared among them")
      ->capture_default_str()->group(texture_group);
  cmd.add_option(p + "existing-occlusion", s.existing_occlusion,
                 "A material's own occlusion texture: multiply (times the bake) or replace")
      ->capture_default_str()->group(texture_group);
  cmd.add_flag(p + "per-instance", t.per_instance,
               "A mesh placed by several nodes: each placement its own material copy and texture (default: averaged)")
      ->group(texture_group);
  cmd.add_option(p + "dump-texture", t.dump, "Also write each texture as float EXR into this folder")->group(texture_group);
}

Result<ao::Request> ao_request(const AoSettings& s, const std::string& prefix) {
  ao::Request r = s.request;
  const auto into = ao::into_from_names(s.into, s.existing_colors);
  if (!into) {
    return Error{"", "--" + prefix + "into '" + s.into + "' --" + prefix + "existing-colors '" + s.existing_colors +
                         "': use COLOR_0 (with multiply or replace) or _AO", true};
  }
  r.into = *into;
  if (Status st = ao::check(r.options); !st) return st.error();
  if (!s.texture.empty()) {
    const auto size = ao::texture_size_from_text(s.texture);
    if (!size) return Error{"", "--" + prefix + "texture '" + s.texture + "': use a size such as 1024 or 2048x1024", true};
    if (s.existing_occlusion != "multiply" && s.existing_occlusion != "replace") {
      return Error{"", "--" + prefix + "existing-occlusion '" + s.existing_occlusion + "': use multiply or replace", true};
    }
    r.texture = s.texture_request;
    r.texture->size.width = size->first, r.texture->size.height = size->second;
    r.texture->multiply_existing = s.existing_occlusion == "multiply";
    if (Status st = ao::check(*r.texture, r.options); !st) return st.error();
  }
  return r;
}

void print_texture_reports(const std::vector<exporter::TextureReport>& textures) {
  for (const exporter::TextureReport& t : textures) {
    const double mapped = double(t.covered + t.touched);
    if (t.node >= 0) std::printf("node %d, ", t.node);
    std::printf("material %d '%s': %s, %dx%d over TEXCOORD_%d, %zu texels mapped (%zu on seams), %.1f%% of them overlapped, "
                "%zu padded, mean %.4f%s\n",
                t.material, t.name.c_str(), t.file.c_str(), t.width, t.height, t.texcoord, t.covered + t.touched, t.touched,
                mapped > 0 ? 100.0 * double(t.overlapped) / mapped : 0.0, t.padded, t.mean,
                t.existing.empty() ? "" : (", its own occlusion texture " + t.existing).c_str());
    if (t.wrapped) std::printf("  %zu triangles reach outside [0, 1]: wrapped by the sampler's mode\n", t.wrapped);
    if (t.degenerate_uv) std::printf("  %zu triangles with no UV area skipped\n", t.degenerate_uv);
    if (t.too_large) std::printf("  %zu triangles spanning more than 64 copies of the texture skipped\n", t.too_large);
    if (t.instances_without_uv) {
      std::printf("  %zu placed primitives lack TEXCOORD_%d: skipped (per-vertex AO can still be baked)\n",
                  t.instances_without_uv, t.texcoord);
    }
  }
}

}  // namespace matbake::cli
