#pragma once
// The parameters of an AO bake (ao::Request): `bake-ao`'s options, `export --ao-*` and a manifest
// scene's `ao = { ... }`, described once (params.hpp).
#include "matbake/ao.hpp"
#include "matbake/params.hpp"

namespace matbake::ao {

const params::Group<Request>& request_params();

}  // namespace matbake::ao
