#pragma once
// The parameters of preview::Options that a person sets: `preview`'s flags, described once (params.hpp).
#include "matbake/params.hpp"
#include "matbake/preview.hpp"

namespace matbake::preview {

const params::Group<Options>& options_params();

}  // namespace matbake::preview
