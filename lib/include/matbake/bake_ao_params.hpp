#pragma once
// What `bake-ao` is asked, as one tree (params.hpp): the written textures' encoding and format,
// delivery, and the AO request (its flags unprefixed).
#include "matbake/bake_ao.hpp"
#include "matbake/params.hpp"

namespace matbake::bake_ao {
const params::Tree<Options>& request_tree();
}  // namespace matbake::bake_ao
