#pragma once
// The parameters of pack::MaterialOptions: the flags of pack, unpack, workflow, validate and preview
// (each takes those that apply to it) and a manifest material's keys, described once (params.hpp).
#include "matbake/pack.hpp"
#include "matbake/params.hpp"

namespace matbake::pack {

const params::Group<MaterialOptions>& material_params();

}  // namespace matbake::pack
