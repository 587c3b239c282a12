#pragma once
// A primitive's triangles divided among materials: how a UDIM bake gives a glTF one material per
// tile, as Blender's glTF exporter does (a glTF material samples one image per texture, and a
// primitive has one material).
#include <array>
#include <cstdint>
#include <vector>

#include "document.hpp"

namespace matbake::gltf {

struct TriangleGroup {
  int material = -1;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // vertex numbers of the primitive as it is now
};

// Mesh `mesh`'s primitive `primitive` keeps the first group (its indices rewritten as a triangle
// list where there are several); each other group becomes a new primitive of the mesh, after its
// others, with the same attributes, morph targets and extras, and the group's indices and material.
// A Draco-compressed primitive is written uncompressed. Errors: its POSITION unreadable.
Status split_primitive(Document& doc, int mesh, int primitive, const std::vector<TriangleGroup>& groups);

}  // namespace matbake::gltf
