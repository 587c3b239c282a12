#pragma once
// A build's own settings, keys of the manifest with no command-line flag (params.hpp's
// manifest_only): whether and how a material is validated, and how a scene finds its materials.
#include "matbake/params.hpp"
#include "matbake/pipeline.hpp"

namespace matbake::pipeline {

const params::Group<ValidationRules>& validation_params();  // enabled, heatmap
const params::Group<SceneSpec>& scene_params();             // match_names
const params::Group<SceneBake>& bake_source_params();       // from

// A manifest material's request: its options and encoding as its own keys, its validation in its
// `validate` table (validation_params and validate::options_params).
const params::Tree<MaterialSpec>& material_tree();
// A manifest scene's request: match_names, export's request (exporter::request_tree) over its
// options, and its bake: bake_source_params, bake::request_params in table `bake`, the ao and
// bent_normal maps' estimator in `bake.ao`.
const params::Tree<SceneSpec>& scene_tree();

}  // namespace matbake::pipeline
