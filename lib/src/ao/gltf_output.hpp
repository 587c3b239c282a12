#pragma once
// The baked values into a glTF document being written (bake-ao -o, and export).
#include "../gltf/document.hpp"
#include "matbake/ao.hpp"

namespace matbake::ao {

// `doc` must be the file `scene` was loaded from. Adds COLOR_0 or _AO to each baked primitive and
// gives every further node placing a mesh its own copy of it.
void add_to_document(gltf::Document& doc, const scene::Scene& scene, const Bake& bake, Into into);

}  // namespace matbake::ao
