#pragma once
// What `bake` is asked, as one tree (params.hpp): the maps, the cage, the texture, and the PNG
// encoding of the normal map.
#include "matbake/bake_file.hpp"
#include "matbake/params.hpp"

namespace matbake::bake {
const params::Group<Request>& request_params();
const params::Tree<FileOptions>& request_tree();
}  // namespace matbake::bake
