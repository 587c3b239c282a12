#pragma once
// A build's own settings, keys of the manifest with no command-line flag (params.hpp's
// manifest_only): whether and how a material is validated, and how a scene finds its materials.
#include "matbake/params.hpp"
#include "matbake/pipeline.hpp"

namespace matbake::pipeline {

const params::Group<ValidationRules>& validation_params();  // enabled, heatmap
const params::Group<SceneSpec>& scene_params();             // match_names

}  // namespace matbake::pipeline
