// ao::Request's parameters: names, kinds, ranges, help and examples; defaults are the struct's.
#include <cmath>

#include "matbake/ao_params.hpp"
#include "matbake/image.hpp"

namespace matbake::ao {
namespace {

using params::Param;
using params::Spec;
using params::Value;
constexpr double kUnbounded = HUGE_VAL;

// The texture bake's fields: set ones make the texture request (finish() refuses them without
// `texture`); read from a request without one, they show its defaults.
TextureRequest& texture_of(Request& r) { return r.texture ? *r.texture : r.texture.emplace(); }
const TextureRequest& texture_of(const Request& r) {
  static const TextureRequest defaults;
  return r.texture ? *r.texture : defaults;
}

Param<Request> texture_size() {
  Spec spec{.name = "texture",
            .kind = params::Kind::integer_or_text,
            .help = "Bake one occlusion texture of this size (1024, or WxH) per material the scene reaches, over its "
                    "UVs, instead of per-vertex values",
            .example = "16x8"};
  return {std::move(spec),
          [](Request& r, const Value& v) -> std::optional<std::string> {
            std::optional<std::pair<int, int>> size;
            if (const auto* side = std::get_if<std::int64_t>(&v)) {
              if (*side >= 1 && *side <= kMaxTextureSide) size = std::pair{int(*side), int(*side)};
            } else {
              size = image::size_from_text(std::get<std::string>(v));
            }
            if (!size) return "a size such as 1024 or 2048x1024";
            texture_of(r).size.width = size->first, texture_of(r).size.height = size->second;
            return std::nullopt;
          },
          [](const Request& r) -> nlohmann::json {
            if (!r.texture) return nullptr;
            return std::to_string(r.texture->size.width) + "x" + std::to_string(r.texture->size.height);
          }};
}

Param<Request> existing_occlusion() {
  Spec spec{.name = "existing_occlusion",
            .kind = params::Kind::choice,
            .help = "A material's own occlusion texture: multiply (times the bake) or replace",
            .choices = {"multiply", "replace"},
            .example = "replace",
            .needs = {{"texture"}}};
  return {std::move(spec),
          [](Request& r, const Value& v) -> std::optional<std::string> {
            texture_of(r).multiply_existing = std::get<std::string>(v) == "multiply";
            return std::nullopt;
          },
          [](const Request& r) { return nlohmann::json(texture_of(r).multiply_existing ? "multiply" : "replace"); }};
}

Param<Request> bits() {
  return params::png_bits<Request>(Spec{.name = "bits", .help = "Linear PNG bits of the texture: 8 or 16", .example = "16",
                                        .needs = {{"texture"}}},
                                   [](auto& r) -> auto& { return texture_of(r).bits; });
}

params::Group<Request> make_group() {
  params::Group<Request> g;
  g.params = {
      params::integer<Request>(Spec{.name = "samples", .help = "Rays per vertex, or per texel with a texture", .min = 1,
                                    .max = kMaxSamples, .example = "8"},
                               [](auto& r) -> auto& { return r.options.samples; }),
      params::number<Request>(Spec{.name = "relative_distance", .help = "d_max as a fraction of the scene radius",
                                   .min = 0, .max = kUnbounded, .above_min = true, .example = "0.1",
                                   .aliases = {"distance"}, .excludes = {"max_distance"}},
                              [](auto& r) -> auto& { return r.options.relative_distance; }),
      params::number<Request>(Spec{.name = "max_distance",
                                   .help = "d_max in scene units, instead of the relative distance (0: unset)",
                                   .min = 0, .max = kUnbounded, .example = "0.5", .aliases = {"absolute_distance"}},
                              [](auto& r) -> auto& { return r.options.absolute_distance; }),
      params::number<Request>(Spec{.name = "tau", .help = "Falloff rate τ in units of 1/d_max", .min = 0,
                                   .max = kUnbounded, .above_min = true, .example = "2"},
                              [](auto& r) -> auto& { return r.options.tau; }),
      params::choice<Request>(Spec{.name = "falloff",
                                   .help = "μ(x): exponential (1 − e^(−τx), normalized to 1 at d_max) or none "
                                           "(binary AO)",
                                   .example = "none"},
                              [](auto& r) -> auto& { return r.options.falloff; }, kFalloffNames),
      params::number<Request>(Spec{.name = "bias",
                                   .help = "Ray-origin offset along the normal × the vertex's mean edge length",
                                   .min = 0, .max = kUnbounded, .example = "0.001"},
                              [](auto& r) -> auto& { return r.options.bias; }),
      params::flag<Request>(Spec{.name = "two_sided",
                                 .help = "Surfaces seen from behind occlude too (default: only their fronts)",
                                 .example = "true"},
                            [](auto& r) -> auto& { return r.options.two_sided; }),
      params::integer<Request>(Spec{.name = "seed", .help = "Sample scrambling seed (same seed, same values, any thread count)",
                                    .min = 0, .max = 9007199254740992.0, .example = "3"},
                               [](auto& r) -> auto& { return r.options.seed; }),
      params::choice<Request>(Spec{.name = "sampler", .help = "Directions: scrambled Sobol or independent random",
                                   .example = "random"},
                              [](auto& r) -> auto& { return r.options.sampler; }, kSamplerNames),
      params::choice<Request>(Spec{.name = "recompute_normals",
                                   .help = "Replace the file's normals, weighting faces by this (unset: the file's)",
                                   .example = "angle"},
                              [](auto& r) -> auto& { return r.options.recompute_normals; },
                              scene::kNormalWeightingNames),
      {Spec{.name = "fast_traversal",
            .kind = params::Kind::flag,
            .help = "Embree's non-robust traversal: faster, but a ray may slip between triangles sharing an edge",
            .example = "true"},
       [](Request& r, const Value& v) -> std::optional<std::string> {
         r.options.watertight = !std::get<bool>(v);
         return std::nullopt;
       },
       [](const Request& r) { return nlohmann::json(!r.options.watertight); }},
      into_attribute<Request>(Spec{.name = "into",
                                   .help = "Per-vertex values as COLOR_0 (multiplies the base colour in any viewer) or "
                                           "_AO (a float attribute)",
                                   .example = "_AO",
                                   .excludes = {"texture"}},
                              &Request::into),
      into_existing<Request>(Spec{.name = "existing_colors",
                                  .help = "With COLOR_0, a primitive's own COLOR_0: multiply (kept, times AO; alpha "
                                          "kept) or replace",
                                  .example = "replace",
                                  .excludes = {"texture"}},
                             "into", &Request::into),
      texture_size(),
      params::integer<Request>(Spec{.name = "texcoord",
                                    .help = "UV set of the texture (-1: the material's occlusionTexture texCoord, else 0)",
                                    .min = -1, .max = 255, .example = "0", .needs = {{"texture"}}},
                               [](auto& r) -> auto& { return texture_of(r).texcoord; }),
      params::integer<Request>(Spec{.name = "padding",
                                    .help = "Texels around the UV islands that take the nearest island texel's value "
                                            "(-1: 16 at 1024, scaled)",
                                    .min = -1, .max = kMaxTextureSide, .example = "2", .needs = {{"texture"}}},
                               [](auto& r) -> auto& { return texture_of(r).size.padding; }),
      params::integer<Request>(Spec{.name = "texel_samples",
                                    .help = "Surface points per texel, stratified over its footprint; the rays are "
                                            "shared among them",
                                    .min = 1, .max = kMaxSamples, .example = "2", .needs = {{"texture"}}},
                               [](auto& r) -> auto& { return texture_of(r).size.texel_samples; }),
      bits(),
      existing_occlusion(),
      params::flag<Request>(Spec{.name = "per_instance",
                                 .help = "A mesh placed by several nodes: each placement its own material copy and "
                                         "texture (default: averaged)",
                                 .example = "true",
                                 .needs = {{"texture"}}},
                            [](auto& r) -> auto& { return texture_of(r).per_instance; }),
  };
  g.check = [](const Request& r) -> Status {
    if (Status s = check(r.options); !s) return s;
    if (r.texture) return check(*r.texture, r.options);
    return success();
  };
  return g;
}

}  // namespace

const params::Group<Request>& request_params() {
  static const params::Group<Request> group = make_group();
  return group;
}

const params::Group<Request>& estimator_params() {
  static const params::Group<Request> group = [] {
    params::Group<Request> g;
    for (const char* name : {"samples", "relative_distance", "max_distance", "tau", "falloff", "bias", "two_sided", "seed",
                             "sampler", "fast_traversal"}) {
      g.params.push_back(*request_params().find(name));
    }
    g.check = [](const Request& r) { return check(r.options); };
    return g;
  }();
  return group;
}

}  // namespace matbake::ao
