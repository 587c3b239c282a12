#pragma once
// The workflow conversion's error report as JSON, as `workflow --report` and `export --report`
// write it.
#include <nlohmann/json.hpp>

#include "matbake/workflow_maps.hpp"

namespace matbake::cli {

nlohmann::json to_json(const workflow::ErrorStats& s);
nlohmann::json to_json(const workflow::ConversionErrors& e);
nlohmann::json to_json(const workflow::DielectricF0& d);

}  // namespace matbake::cli
