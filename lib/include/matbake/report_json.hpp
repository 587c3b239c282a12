#pragma once
// Reports as JSON, one shape wherever they appear: the workflow conversion's errors (`workflow
// --report`, `export --report`, `build`) and validation results (`validate --json`, `build`).
#include <nlohmann/json.hpp>

#include "matbake/export.hpp"
#include "matbake/validate.hpp"
#include "matbake/workflow_maps.hpp"

namespace matbake {

nlohmann::json to_json(const workflow::ErrorStats& s);
nlohmann::json to_json(const workflow::ConversionErrors& e);
nlohmann::json to_json(const workflow::DielectricF0& d);
// Counts by class and flag, the worst texels, F0 (and diffuse) statistics, and the material
// comparison when options.material is set.
nlohmann::json to_json(const validate::Report& r, const validate::Options& options, bool has_diffuse);
// Materials written (with their conversion errors), what was left out, files written: as
// `export --json` prints it (without its "command" key).
nlohmann::json to_json(const exporter::Report& r);

}  // namespace matbake
