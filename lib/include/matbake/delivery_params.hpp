#pragma once
// The parameters of delivery::Options (docs/delivery.md): export's and bake-ao's flags and a
// manifest scene's keys, described once (params.hpp). A class's settings are named after it:
// colour_codec, data_max_size, normal_zstd, ...
#include "matbake/delivery.hpp"
#include "matbake/params.hpp"

namespace matbake::delivery {

const params::Group<Options>& options_params();

}  // namespace matbake::delivery
