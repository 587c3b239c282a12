#include "vertex_occlusion.hpp"

#include <map>

#include "decode.hpp"

namespace matbake::gltf {

namespace {

// The mesh each node's values go into: the original for the first node placing it, a copy for every
// further one (made here). The node's mesh is read from the document, which may have been pruned
// (meshes renumbered, nodes not) since the values were computed.
std::map<int, int> meshes_of_nodes(Document& doc, std::span<const PlacedValues> placed) {
  Json& json = doc.json;
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
  return mesh_of_node;
}

// The attributes of a primitive gaining per-vertex values: written uncompressed if it was Draco's.
Json& attributes_of(Document& doc, int mesh, int primitive) {
  if (uncompress_draco_primitive(doc, std::size_t(mesh), std::size_t(primitive))) {
    doc.decoded.notes.push_back("mesh " + std::to_string(mesh) + " primitive " + std::to_string(primitive) +
                                ": written uncompressed (KHR_draco_mesh_compression dropped), as its vertices gained values");
  }
  return doc.json["meshes"][std::size_t(mesh)]["primitives"][std::size_t(primitive)]["attributes"];
}

}  // namespace

void add_vertex_scalars(Document& doc, std::span<const PlacedValues> placed, const std::string& attribute) {
  const std::map<int, int> mesh_of_node = meshes_of_nodes(doc, placed);
  for (const PlacedValues& p : placed) {
    if (p.values.empty()) continue;
    attributes_of(doc, mesh_of_node.at(p.node), p.primitive)[attribute] =
        add_float_accessor(doc, {p.values.begin(), p.values.end()}, p.values.size(), "SCALAR");
  }
}

void add_vertex_occlusion(Document& doc, std::span<const PlacedValues> placed, ao::Into into) {
  if (into == ao::Into::attribute) return add_vertex_scalars(doc, placed, "_AO");
  const std::map<int, int> mesh_of_node = meshes_of_nodes(doc, placed);
  for (const PlacedValues& p : placed) {
    const std::span<const float> w = p.values;
    if (w.empty()) continue;
    const bool multiply = into == ao::Into::color_multiply && !p.colors.empty();
    const bool alpha = multiply && p.colors_have_alpha;
    const std::size_t components = alpha ? 4 : 3;
    std::vector<float> colors(w.size() * components);
    for (std::size_t v = 0; v < w.size(); ++v) {
      for (std::size_t c = 0; c < 3; ++c) colors[v * components + c] = multiply ? p.colors[v][int(c)] * w[v] : w[v];
      if (alpha) colors[v * components + 3] = p.colors[v].a;
    }
    attributes_of(doc, mesh_of_node.at(p.node), p.primitive)["COLOR_0"] = add_float_accessor(doc, colors, w.size(), alpha ? "VEC4" : "VEC3");
  }
}

}  // namespace matbake::gltf
