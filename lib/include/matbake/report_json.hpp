#pragma once
// Reports as JSON, one shape wherever they appear: the workflow conversion's errors (`workflow
// --report`, `export --report`, `build`) and validation results (`validate --json`, `build`).
#include <nlohmann/json.hpp>

#include "matbake/bake_file.hpp"
#include "matbake/export.hpp"
#include "matbake/validate.hpp"
#include "matbake/workflow_maps.hpp"

namespace matbake {

nlohmann::json to_json(const workflow::ErrorStats& s);
nlohmann::json to_json(const workflow::ConversionErrors& e);
nlohmann::json to_json(const workflow::DielectricF0& d);
// A workflow conversion (`workflow --json` and --report, a build's material job): direction,
// mapping, texels, errors, and from spec-gloss the Khronos converter's errors and the dielectric
// F0 extensions; null when nothing was converted.
nlohmann::json to_json(const workflow::LayoutMaps& converted, workflow::RoughnessMapping mapping);
// Counts by class and flag, the worst texels, F0 (and diffuse) statistics, and the material
// comparison when options.material is set.
nlohmann::json to_json(const validate::Report& r, const validate::Options& options);
// The validation report file (`validate --report`, a build's NAME.validation.json): to_json plus
// max_violations and passed.
Status write_validation_report(const validate::Report& r, const validate::Options& options,
                               const std::filesystem::path& json);
// Materials written (with their conversion errors), what was left out, files written: as
// `export --json` prints it (without its "command" key).
nlohmann::json to_json(const exporter::Report& r);
// Options by the names the manifest uses (a build's stamp records them; material maps not included).
nlohmann::json to_json(const ao::Request& r);
// One material's baked occlusion texture, as bake-ao and export report it.
nlohmann::json to_json(const bake_ao::TextureReport& t);
nlohmann::json to_json(const exporter::Options& o);
nlohmann::json to_json(const delivery::TextureReport& t);
nlohmann::json delivered_json(const std::vector<delivery::TextureReport>& textures);
// A bake: the cage, each material's texture set (rays, misses, height range, files), tangents,
// times, notes, files written and maps reused (kept from an earlier bake), as `bake --json` prints it (without its "command" and paths).
nlohmann::json to_json(const bake::FileReport& r);

}  // namespace matbake
