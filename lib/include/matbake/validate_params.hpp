#pragma once
// The parameters of validate::Options that a person sets: `validate`'s options and a manifest's
// `validate = { ... }` keys (besides `enabled` and `heatmap`), described once (params.hpp).
#include "matbake/params.hpp"
#include "matbake/validate.hpp"

namespace matbake::validate {

const params::Group<Options>& options_params();

}  // namespace matbake::validate
