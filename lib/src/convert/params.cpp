#include "matbake/convert_params.hpp"

namespace matbake::convert {

const params::Group<Options>& options_params() {
  using params::Spec;
  static const params::Group<Options> group{{
      params::text<Options>(Spec{.name = "from",
                                 .help = "Encoding of the inputs: srgb, gamma2.2, linear, or an OCIO colour space",
                                 .example = "gamma2.2"},
                            [](auto& o) -> auto& { return o.from; }),
      params::text<Options>(Spec{.name = "to",
                                 .help = "Encoding of the outputs: linear, srgb, gamma2.2, or an OCIO colour space",
                                 .example = "srgb"},
                            [](auto& o) -> auto& { return o.to; }),
      params::choice<Options>(Spec{.name = "bits",
                                   .help = "Output samples, 8 or 16 for PNG, half or float for EXR, any for TIFF "
                                           "(unset: half for EXR; else 16 for a linear target, the input's depth "
                                           "otherwise)",
                                   .example = "16"},
                              [](auto& o) -> auto& { return o.bits; }, image::kSampleTypeNames),
      params::text<Options>(Spec{.name = "format",
                                 .help = "Output format of files written into a folder (unset: exr for a linear target, else png)",
                                 .choices = {"exr", "png", "tif"},
                                 .example = "tif"},
                            [](auto& o) -> auto& { return o.format; }),
      params::text<Options>(Spec{.name = "compression",
                                 .help = "EXR/TIFF: OIIO's compression name, e.g. none, zip, zips, zip:1..9, piz, dwaa "
                                         "(unset: zip for EXR)",
                                 .example = "piz"},
                            [](auto& o) -> auto& { return o.compression; }),
  }};
  return group;
}

}  // namespace matbake::convert
