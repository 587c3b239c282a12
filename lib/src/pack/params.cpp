#include "matbake/material_params.hpp"

namespace matbake::pack {
namespace {

// "256" or "512x256": the size of textures made of constants alone (load_sources checks it against
// the pixel limit, which --max-pixels may have raised by then).
params::Param<MaterialOptions> constant_size() {
  return {params::Spec{.name = "size",
                       .kind = params::Kind::integer_or_text,
                       .help = "Size of the textures when every source is a constant: 256 or WxH (unset: 1x1)",
                       .example = "16x8"},
          [](MaterialOptions& o, const params::Value& v) -> std::optional<std::string> {
            std::optional<std::pair<int, int>> size;
            if (const auto* side = std::get_if<std::int64_t>(&v)) {
              if (*side >= 1 && *side <= INT32_MAX) size = std::pair{int(*side), int(*side)};
            } else {
              size = image::size_from_text(std::get<std::string>(v));
            }
            if (!size || size->first < 1 || size->second < 1) return "a size such as 256 or 512x256";
            o.width = size->first, o.height = size->second;
            return std::nullopt;
          },
          [](const MaterialOptions& o) -> nlohmann::json {
            if (o.width == 0) return nullptr;
            return std::to_string(o.width) + "x" + std::to_string(o.height);
          }};
}

}  // namespace

const params::Group<MaterialOptions>& material_params() {
  using params::Spec;
  static const params::Group<MaterialOptions> group{{
      params::choice<MaterialOptions>(Spec{.name = "transfer",
                                           .help = "Curve of 8-bit colour: how 8-bit colour sources were authored and "
                                                   "how 8-bit colour textures are written",
                                           .example = "gamma2.2"},
                                      [](auto& o) -> auto& { return o.transfer; }, color::kTransferNames),
      params::choice<MaterialOptions>(Spec{.name = "decode",
                                           .help = "Curve of every colour input, overriding its own tag and the "
                                                   "rule for untagged files (8-bit: transfer; deeper: linear)",
                                           .example = "linear",
                                           .aliases = {"input_transfer"}},
                                      [](auto& o) -> auto& { return o.decode; }, color::kTransferNames),
      params::choice<MaterialOptions>(Spec{.name = "normal_y",
                                           .help = "Which way a normal map source's green channel points: opengl "
                                                   "(+Y, glTF's and Blender's) or directx (-Y, Unreal's; flipped on read)",
                                           .example = "directx"},
                                      [](auto& o) -> auto& { return o.normal_y; }, kNormalConventionNames),
      params::flag<MaterialOptions>(Spec{.name = "resize",
                                         .help = "Resample sources of different sizes to the largest (in linear "
                                                 "light); else they are an error",
                                         .example = "true"},
                                    [](auto& o) -> auto& { return o.resize; }),
      constant_size(),
      params::choice<MaterialOptions>(Spec{.name = "bits",
                                           .help = "Samples of the written textures (unset: half for .exr, else 8); "
                                                   "colour is encoded with transfer in 8-bit, linear otherwise",
                                           .example = "16",
                                           .written_only = true},
                                      [](auto& o) -> auto& { return o.bits; }, image::kSampleTypeNames),
      params::text<MaterialOptions>(Spec{.name = "format",
                                         .help = "Format of the textures where no output path names one (a "
                                                 "manifest material's, unpack's maps)",
                                         .choices = {"png", "exr", "tif"},
                                         .example = "exr",
                                         .written_only = true},
                                    [](auto& o) -> auto& { return o.format; }),
      params::choice<MaterialOptions>(Spec{.name = "mapping",
                                           .help = "Gloss ⇄ roughness of a workflow conversion (fitted: least "
                                                   "squares over the lobe)",
                                           .example = "walter"},
                                      [](auto& o) -> auto& { return o.mapping; }, workflow::kRoughnessMappingNames),
  }};
  return group;
}

}  // namespace matbake::pack
