#include "matbake/export_params.hpp"

#include "matbake/ao_params.hpp"
#include "matbake/delivery_params.hpp"
#include "matbake/encoding_params.hpp"

namespace matbake::exporter {

const params::Group<Options>& options_params() {
  using params::Spec;
  static const params::Group<Options> group{{
      params::choice<Options>(Spec{.name = "dielectric_f0",
                                   .help = "A converted dielectric whose F0 is not 0.04: KHR_materials_specular, "
                                           "KHR_materials_ior, or none (core glTF's 0.04)",
                                   .example = "ior"},
                              [](auto& o) -> auto& { return o.dielectric_f0; }, kDielectricF0Names),
      params::choice<Options>(Spec{.name = "mapping",
                                   .help = "Gloss → roughness of the glTF's own spec-gloss materials (and of export's "
                                           "Schüler pairs; a manifest material brings its own)",
                                   .example = "walter"},
                              [](auto& o) -> auto& { return o.mapping; }, workflow::kRoughnessMappingNames),
      params::flag<Options>(Spec{.name = "orm",
                                 .help = "Pack occlusion and metallic-roughness textures of a material into one ORM "
                                         "texture (false keeps them apart)",
                                 .example = "false"},
                            [](auto& o) -> auto& { return o.pack_orm; }),
  }};
  return group;
}

const params::Tree<Options>& request_tree() {
  static const params::Tree<Options> tree{
      params::branch<Options>(image::encoding_params(), "", "", [](auto& o) -> auto& { return o.encoding; }),
      params::branch<Options>(options_params(), "", "", [](auto& o) -> auto& { return o; }),
      params::branch<Options>(delivery::options_params(), "", "", [](auto& o) -> auto& { return o.delivery; }),
      params::optional_branch<Options>(ao::request_params(), "ao", "ao-", &Options::ao),
  };
  return tree;
}

}  // namespace matbake::exporter
