#include "vertex_occlusion.hpp"

#include <map>

#include "decode.hpp"

namespace matbake::gltf {

void add_vertex_occlusion(Document& doc, std::span<const PlacedValues> placed, ao::Into into) {
  Json& json = doc.json;

  // The mesh each node writes into: the original for the first node placing it, a copy for every
  // further one. The node's mesh is read from the document, which may have been pruned (meshes
  // renumbered, nodes not) since the values were computed.
  std::map<int, int> owner_of_mesh;  // mesh → the node that keeps it
  std::map<int, int> mesh_of_node;   // node → the mesh its values go into
  for (const PlacedValues& p : placed) {
    if (p.values.empty() || mesh_of_node.contains(p.node)) continue;
    const int mesh = json["nodes"][std::size_t(p.node)]["mesh"].get<int>();
    if (owner_of_mesh.try_emplace(mesh, p.node).second) {
      mesh_of_node[p.node] = mesh;
      continue;
    }
    json["meshes"].push_back(json["meshes"][std::size_t(mesh)]);
    const int copy = int(json["meshes"].size()) - 1;
    json["nodes"][std::size_t(p.node)]["mesh"] = copy;
    mesh_of_node[p.node] = copy;
  }

  for (const PlacedValues& p : placed) {
    const std::span<const float> w = p.values;
    if (w.empty()) continue;
    const std::size_t mesh = std::size_t(mesh_of_node.at(p.node));
    if (uncompress_draco_primitive(doc, mesh, std::size_t(p.primitive))) {
      doc.decoded.notes.push_back("mesh " + std::to_string(mesh) + " primitive " + std::to_string(p.primitive) +
                                  ": written uncompressed (KHR_draco_mesh_compression dropped), as its vertices gained occlusion");
    }
    Json& attributes = json["meshes"][std::size_t(mesh_of_node.at(p.node))]["primitives"][std::size_t(p.primitive)]["attributes"];
    if (into == ao::Into::attribute) {
      attributes["_AO"] = add_float_accessor(doc, {w.begin(), w.end()}, w.size(), "SCALAR");
      continue;
    }
    const bool multiply = into == ao::Into::color_multiply && !p.colors.empty();
    const bool alpha = multiply && p.colors_have_alpha;
    const std::size_t components = alpha ? 4 : 3;
    std::vector<float> colors(w.size() * components);
    for (std::size_t v = 0; v < w.size(); ++v) {
      for (std::size_t c = 0; c < 3; ++c) colors[v * components + c] = multiply ? p.colors[v][int(c)] * w[v] : w[v];
      if (alpha) colors[v * components + 3] = p.colors[v].a;
    }
    attributes["COLOR_0"] = add_float_accessor(doc, colors, w.size(), alpha ? "VEC4" : "VEC3");
  }
}

}  // namespace matbake::gltf
