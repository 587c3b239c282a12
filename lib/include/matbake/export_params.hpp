#pragma once
// The parameters of exporter::Options that a person sets (its materials and AO come from their own
// descriptions): `export`'s options and a manifest scene's keys, described once (params.hpp).
#include "matbake/export.hpp"
#include "matbake/params.hpp"

namespace matbake::exporter {

const params::Group<Options>& options_params();
// Everything an export (and a manifest scene) is asked: the glTF's textures (encoding, format),
// export's own options, delivery and AO (the "ao" table; on the command line --ao-*).
const params::Tree<Options>& request_tree();

}  // namespace matbake::exporter
