#pragma once
// Meshes joined for delivery (`join_meshes`, docs/delivery.md "Geometry"), as gltfpack does by
// default and glTF-Transform's flatten + join: each mesh placed by one node that nothing moves goes
// into world space, and its primitives join those of the same material and attributes, in one mesh
// placed by one new root node; nodes left empty are removed. Fewer and longer streams: fewer draw
// calls, less JSON, better meshopt compression. Kept as placed: meshes placed by several nodes or
// sharing their vertices with another mesh (instances stay instances, not copies), skinned and morphed meshes, nodes an animation moves and
// what is below them, nodes with extensions, primitives that are not triangles or not floats.
#include <string>
#include <vector>

#include "../gltf/document.hpp"

namespace matbake::delivery {

// Returns lines for the report. Errors name the file and the primitive.
Result<std::vector<std::string>> join_meshes(gltf::Document& doc);

}  // namespace matbake::delivery
