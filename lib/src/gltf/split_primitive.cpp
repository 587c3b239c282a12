#include "split_primitive.hpp"

#include "decode.hpp"

namespace matbake::gltf {

Status split_primitive(Document& doc, int mesh, int primitive, const std::vector<TriangleGroup>& groups) {
  if (groups.empty()) return success();
  Json& primitives = doc.json["meshes"][std::size_t(mesh)]["primitives"];
  if (groups.size() == 1) {  // one material: the triangles stay as they are
    primitives[std::size_t(primitive)]["material"] = groups[0].material;
    return success();
  }
  uncompress_draco_primitive(doc, std::size_t(mesh), std::size_t(primitive));
  auto positions = accessor_bytes(doc, size_in(primitives[std::size_t(primitive)]["attributes"], "POSITION", SIZE_MAX));
  if (!positions) return positions.error();
  const std::size_t vertices = positions->count;
  const Json original = primitives[std::size_t(primitive)];
  for (std::size_t g = 0; g < groups.size(); ++g) {
    std::vector<std::uint32_t> indices;
    indices.reserve(3 * groups[g].triangles.size());
    for (const auto& triangle : groups[g].triangles) indices.insert(indices.end(), triangle.begin(), triangle.end());
    Json made = original;
    made["indices"] = add_index_accessor(doc, indices, vertices);
    made.erase("mode");  // a triangle list
    made["material"] = groups[g].material;
    if (g == 0) {
      doc.json["meshes"][std::size_t(mesh)]["primitives"][std::size_t(primitive)] = std::move(made);
    } else {
      doc.json["meshes"][std::size_t(mesh)]["primitives"].push_back(std::move(made));
    }
  }
  return success();
}

}  // namespace matbake::gltf
