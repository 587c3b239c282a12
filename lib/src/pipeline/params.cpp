#include "matbake/pipeline_params.hpp"

namespace matbake::pipeline {

const params::Group<ValidationRules>& validation_params() {
  using params::Spec;
  static const params::Group<ValidationRules> group{{
      params::flag<ValidationRules>(Spec{.name = "enabled",
                                         .help = "Validate the material (its report OUT/materials/NAME.validation.json)",
                                         .example = "false",
                                         .manifest_only = true},
                                    [](auto& r) -> auto& { return r.enabled; }),
      params::flag<ValidationRules>(Spec{.name = "heatmap",
                                         .help = "Also write the validation's heatmap, OUT/materials/NAME_validation.png "
                                                 "(validate --heatmap FILE)",
                                         .example = "true",
                                         .manifest_only = true},
                                    [](auto& r) -> auto& { return r.heatmap; }),
  }};
  return group;
}

const params::Group<SceneSpec>& scene_params() {
  using params::Spec;
  static const params::Group<SceneSpec> group{{
      params::flag<SceneSpec>(Spec{.name = "match_names",
                                   .help = "glTF materials named like a manifest material get it, besides those "
                                           "`materials` assigns",
                                   .example = "false",
                                   .manifest_only = true},
                              [](auto& s) -> auto& { return s.match_names; }),
  }};
  return group;
}

}  // namespace matbake::pipeline
