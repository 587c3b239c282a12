// delivery::Options' parameters. The per-class settings are made for each class from one list, so
// colour_*, data_* and normal_* cannot drift apart.
#include <cmath>

#include "matbake/delivery_params.hpp"
#include "profiles.hpp"

namespace matbake::delivery {
namespace {

using params::Param;
using params::Spec;
constexpr int kMaxSide = 16384;

// An integer setting whose 0 means "none": shown as null (no value) rather than 0.
Param<Options> optional_integer(Spec spec, TextureClass c, int ClassOptions::*field) {
  auto p = params::integer<Options>(std::move(spec), [c, field](auto& o) -> auto& { return o.of(c).*field; });
  p.get = [c, field](const Options& o) -> nlohmann::json {
    if (o.of(c).*field == 0) return nullptr;
    return o.of(c).*field;
  };
  return p;
}

void add_class(std::vector<Param<Options>>& out, TextureClass c) {
  const std::string name(name_in(kTextureClassNames, c));
  const std::string what = c == TextureClass::colour ? "colour textures (baseColor, emissive)"
                           : c == TextureClass::data ? "data textures (metallic-roughness, occlusion, ORM)"
                                                     : "normal maps";
  const auto field = [c](auto member) { return [c, member](auto& o) -> auto& { return o.of(c).*member; }; };
  // Codec settings act only in KTX2, each only under its codec.
  const params::Condition ktx2{"texture_format", "ktx2"};
  const auto under = [&](Codec codec) { return std::vector<params::Condition>{ktx2, {name + "_codec", std::string(name_in(kCodecNames, codec))}}; };
  out.push_back(params::choice<Options>(Spec{.name = name + "_codec",
                                             .help = "Codec of " + what + " in KTX2: etc1s, uastc, or png "
                                                     "(kept as PNG)",
                                             .example = c == TextureClass::colour ? "uastc" : "etc1s",
                                             .needs = {ktx2}},
                                        field(&ClassOptions::codec), kCodecNames));
  out.push_back(params::integer<Options>(Spec{.name = name + "_quality", .help = "ETC1S quality of " + what + " (basisu -q)",
                                              .min = 1, .max = 255, .example = "200", .needs = under(Codec::etc1s)},
                                         field(&ClassOptions::quality)));
  out.push_back(params::integer<Options>(Spec{.name = name + "_uastc_level",
                                              .help = "UASTC encoding level of " + what + " (basisu -uastc_level; higher: "
                                                      "slower, closer)",
                                              .min = 0, .max = 4, .example = "3", .needs = under(Codec::uastc)},
                                         field(&ClassOptions::uastc_level)));
  out.push_back(params::number<Options>(Spec{.name = name + "_uastc_rdo",
                                             .help = "UASTC rate-distortion λ of " + what + " (basisu -uastc_rdo_l): higher "
                                                     "compresses better under zstd, with more error; 0 off",
                                             .min = 0, .max = 100, .example = "1", .needs = under(Codec::uastc)},
                                        field(&ClassOptions::uastc_rdo)));
  out.push_back(params::integer<Options>(Spec{.name = name + "_uastc_rdo_dictionary",
                                              .help = "Bytes of earlier blocks UASTC rate-distortion of " + what +
                                                      " searches for matches (basisu -uastc_rdo_d): smaller is faster and "
                                                      "compresses less",
                                              .min = 64, .max = 65536, .example = "1024", .needs = under(Codec::uastc)},
                                         field(&ClassOptions::uastc_rdo_dictionary)));
  out.push_back(params::integer<Options>(Spec{.name = name + "_zstd",
                                              .help = "zstd supercompression level of UASTC " + what + "; 0 none",
                                              .min = 0, .max = 22, .example = "6", .needs = under(Codec::uastc)},
                                         field(&ClassOptions::zstd)));
  out.push_back(optional_integer(Spec{.name = name + "_max_size",
                                      .help = "Longest side of " + what + " at most this many texels (any texture "
                                              "format); none when not given",
                                      .min = 1, .max = kMaxSide, .example = "512"},
                                 c, &ClassOptions::max_size));
  out.push_back(params::number<Options>(Spec{.name = name + "_scale",
                                             .help = "Scale of " + what + " (any texture format), before max_size and rounding",
                                             .min = 0, .max = 1, .above_min = true, .example = "0.5"},
                                        field(&ClassOptions::scale)));
}

Param<Options> profile_param() {
  Spec spec{.name = "delivery_profile",
            .help = "Start from a delivery profile (presets/delivery/: web, mobile, desktop, archive); the "
                    "settings given beside it override its values",
            .example = "web"};
  spec.kind = params::Kind::choice;
  spec.choices = profile_names();
  return {std::move(spec), [](Options& o, const params::Value& v) { return apply_profile(o, std::get<std::string>(v)); },
          [](const Options& o) -> nlohmann::json {
            if (o.profile.empty()) return nullptr;
            return o.profile;
          }};
}

void add_geometry(std::vector<Param<Options>>& out) {
  const params::Condition quantized{"mesh_quantization", "true"};
  out.push_back(params::flag<Options>(Spec{.name = "join_meshes",
                                           .help = "Move meshes that one node places and nothing animates into world space and "
                                                   "join primitives of one material into one (as gltfpack does); their nodes' "
                                                   "names go",
                                           .example = "true"},
                                      [](auto& o) -> auto& { return o.geometry.join; }));
  out.push_back(params::flag<Options>(Spec{.name = "mesh_quantization",
                                           .help = "Store vertex attributes as integers (KHR_mesh_quantization): positions "
                                                   "of position_bits per mesh, normals and tangents in bytes, UVs of "
                                                   "texcoord_bits, colours in bytes",
                                           .example = "true"},
                                      [](auto& o) -> auto& { return o.geometry.quantize; }));
  out.push_back(params::integer<Options>(Spec{.name = "position_bits",
                                              .help = "Bits of a quantized position along the mesh's longest side",
                                              .min = 8, .max = 16, .example = "16", .needs = {quantized}},
                                         [](auto& o) -> auto& { return o.geometry.position_bits; }));
  out.push_back(params::integer<Options>(Spec{.name = "texcoord_bits",
                                              .help = "Bits of a quantized texture coordinate over its set's range",
                                              .min = 8, .max = 16, .example = "14", .needs = {quantized}},
                                         [](auto& o) -> auto& { return o.geometry.texcoord_bits; }));
  out.push_back(params::choice<Options>(Spec{.name = "mesh_compression",
                                             .help = "Compression of vertex and index buffers: none, or meshopt "
                                                     "(EXT_meshopt_compression, required by the file)",
                                             .example = "meshopt"},
                                        [](auto& o) -> auto& { return o.geometry.compression; }, kMeshCompressionNames));
}

}  // namespace

const params::Group<Options>& options_params() {
  static const params::Group<Options> group = [] {
    params::Group<Options> g;
    // First: both doors apply a group's parameters in this order, so that those given beside the
    // profile override its values.
    g.params.push_back(profile_param());
    g.params.push_back(params::choice<Options>(
        Spec{.name = "texture_format",
             .help = "Format of the textures written into a glTF: png or webp (lossless, 8-bit; the file then "
                     "requires EXT_texture_webp) for those it makes (converted, ORM, occlusion), or ktx2: every "
                     "texture the scene uses as KTX2 (KHR_texture_basisu, docs/delivery.md)",
             .example = "webp"},
        [](auto& o) -> auto& { return o.texture_format; }, kTextureFormatNames));
    for (TextureClass c : {TextureClass::colour, TextureClass::data, TextureClass::normal}) add_class(g.params, c);
    g.params.push_back(params::choice<Options>(Spec{.name = "texture_rounding",
                                                    .help = "Rounding of resized textures' sides: power-of-two, multiple-of-4 "
                                                            "(what KTX2 needs; 1 and 2 stay), or none; never above the source",
                                                    .example = "power-of-two"},
                                               [](auto& o) -> auto& { return o.rounding; }, kRoundingNames));
    g.params.push_back(params::choice<Options>(Spec{.name = "mip_filter",
                                                    .help = "Filter of resizes and mip levels: box (area mean, as runtimes make mips) or kaiser (windowed sinc)",
                                                    .example = "kaiser"},
                                               [](auto& o) -> auto& { return o.filter; }, kFilterNames));
    g.params.push_back(params::flag<Options>(Spec{.name = "mipmaps",
                                                  .help = "Give KTX2 textures a full mip chain (false: level 0 only, sampled without mipmap filtering)",
                                                  .example = "false",
                                                  .needs = {{"texture_format", "ktx2"}}},
                                             [](auto& o) -> auto& { return o.mipmaps; }));
    g.params.push_back(params::flag<Options>(Spec{.name = "keep_alpha_coverage",
                                                  .help = "Scale the alpha of each resized level of a MASK material's textures so that "
                                                          "as many texels pass its alphaCutoff as in the source (foliage and "
                                                          "lettering keep their thickness far away; UASTC, PNG and WebP: an ETC1S "
                                                          "chain is basisu's own)",
                                                  .example = "true"},
                                             [](auto& o) -> auto& { return o.keep_alpha_coverage; }));
    g.params.push_back(params::flag<Options>(Spec{.name = "png_fallback",
                                                  .help = "Keep each KTX2 texture's PNG as its core source, so that "
                                                          "KHR_texture_basisu is used but not required",
                                                  .example = "true",
                                                  .needs = {{"texture_format", "ktx2"}}},
                                             [](auto& o) -> auto& { return o.png_fallback; }));
    g.params.push_back(params::flag<Options>(Spec{.name = "measure_levels",
                                                  .help = "Measure each KTX2 level as a GPU is given it (basisu transcodes it to "
                                                          "BC7) against the level made from the source: PSNR, normals' angles, "
                                                          "MASK coverage, in the report (false saves ~15% of encode time)",
                                                  .example = "false",
                                                  .needs = {{"texture_format", "ktx2"}}},
                                             [](auto& o) -> auto& { return o.measure_levels; }));
    g.params.push_back(params::number<Options>(Spec{.name = "texel_density",
                                                    .help = "Size each texture for this many texels per scene unit, from the "
                                                            "UVs (and texture transforms) that read it; 0 off",
                                                    .min = 0, .max = 1e9, .example = "256"},
                                               [](auto& o) -> auto& { return o.texel_density; }));
    add_geometry(g.params);
    return g;
  }();
  return group;
}

}  // namespace matbake::delivery
