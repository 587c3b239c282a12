#pragma once
// TANGENT written into a primitive, with NORMAL where it has none (glTF: without NORMAL a runtime
// makes flat normals and ignores TANGENT). A vertex whose corners need different tangents or
// normals (a mirror seam, a UV seam MikkTSpace splits, a flat face) is split: the copies go after
// the primitive's vertices, every attribute and morph target gathered for them, and its indices
// rewritten as a triangle list. Vertices keep their numbers, so accessors' min and max stay true.
// A Draco-compressed primitive is written uncompressed.
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <vector>

#include "document.hpp"

namespace matbake::gltf {

struct PrimitiveTangents {
  int mesh = -1, primitive = -1;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // vertex indices, in the file's winding
  std::vector<glm::vec4> tangents;                      // per corner of `triangles`
  std::vector<glm::vec3> normals;                       // per corner: written where NORMAL is missing
};

struct AddedTangents {
  std::size_t vertices = 0;              // added (copies of split vertices)
  std::vector<std::uint32_t> triangles;  // the primitive's triangles as written: 3 vertex numbers each
};
// Errors: an attribute the document cannot read.
Result<AddedTangents> add_tangents(Document& doc, const PrimitiveTangents& primitive);

}  // namespace matbake::gltf
