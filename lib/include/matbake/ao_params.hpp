#pragma once
// The parameters of an AO bake (ao::Request): `bake-ao`'s options, `export --ao-*` and a manifest
// scene's `ao = { ... }`, described once (params.hpp).
#include "matbake/ao.hpp"
#include "matbake/params.hpp"

namespace matbake::ao {

const params::Group<Request>& request_params();
// Of those, the estimator's own (Request::options: samples, distances, falloff, bias, sides, seed,
// sampler, traversal), for a bake that traces AO from points it finds itself (bake's `ao-*`).
const params::Group<Request>& estimator_params();

}  // namespace matbake::ao
