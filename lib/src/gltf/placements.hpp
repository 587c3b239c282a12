#pragma once
// Each placement of a mesh its own material, for a texture bake whose placements need their own
// texture (bake-ao --per-instance, bake --per-instance).
#include <vector>

#include "document.hpp"
#include "matbake/scene.hpp"

namespace matbake::gltf {

// For target t of material materials[t] placed by node nodes[t] (−1: every placement, left alone):
// the node gets its own copy of its mesh (the first node placing a mesh, in scene order, keeps the
// original), and each target after the first of a material a copy of it, named "<name> (<node
// name>)", set on the primitives of the node's mesh that used it. Returns each target's material.
std::vector<int> split_placements(Document& doc, const scene::Scene& scene, const std::vector<int>& materials,
                                  const std::vector<int>& nodes);

}  // namespace matbake::gltf
