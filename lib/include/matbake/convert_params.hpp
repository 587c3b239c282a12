#pragma once
// The parameters of convert::Options: `convert`'s flags, described once (params.hpp).
#include "matbake/convert.hpp"
#include "matbake/params.hpp"

namespace matbake::convert {

const params::Group<Options>& options_params();

}  // namespace matbake::convert
