#pragma once
// Per-vertex AO baked over a scene and written into the document it was built from.
#include "../gltf/document.hpp"
#include "matbake/ao.hpp"

namespace matbake::bake_ao {

Result<ao::Bake> bake_into(gltf::Document& doc, const scene::Scene& scene, const ao::Request& request);

}  // namespace matbake::bake_ao
