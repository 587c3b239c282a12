#include <map>

#include "gltf_output.hpp"

namespace matbake::ao {

void add_to_document(gltf::Document& doc, const scene::Scene& scene, const Bake& bake, Into into) {
  gltf::Json& json = doc.json;

  // The mesh each baked node writes into: the original for the first node placing it, a copy
  // for every further one. The node's mesh is read from the document, which may have been pruned
  // (meshes renumbered, nodes not) since the scene was loaded.
  std::map<int, int> owner_of_mesh;   // mesh → the node that keeps it
  std::map<int, int> mesh_of_node;    // node → the mesh its values go into
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const scene::Instance& inst = scene.instances[k];
    if (bake.values[k].empty() || mesh_of_node.contains(inst.node)) continue;
    const int mesh = json["nodes"][std::size_t(inst.node)]["mesh"].get<int>();
    const auto [owner, first] = owner_of_mesh.try_emplace(mesh, inst.node);
    if (first) {
      mesh_of_node[inst.node] = mesh;
      continue;
    }
    json["meshes"].push_back(json["meshes"][std::size_t(mesh)]);
    const int copy = int(json["meshes"].size()) - 1;
    json["nodes"][std::size_t(inst.node)]["mesh"] = copy;
    mesh_of_node[inst.node] = copy;
  }

  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const scene::Instance& inst = scene.instances[k];
    const std::vector<float>& w = bake.values[k];
    if (w.empty()) continue;
    gltf::Json& attributes =
        json["meshes"][std::size_t(mesh_of_node.at(inst.node))]["primitives"][std::size_t(inst.primitive)]["attributes"];
    if (into == Into::attribute) {
      attributes["_AO"] = gltf::add_float_accessor(doc, w, w.size(), "SCALAR");
      continue;
    }
    const bool multiply = into == Into::color_multiply && !inst.colors.empty();
    const bool alpha = multiply && inst.colors_have_alpha;
    const std::size_t components = alpha ? 4 : 3;
    std::vector<float> colors(w.size() * components);
    for (std::size_t v = 0; v < w.size(); ++v) {
      for (std::size_t c = 0; c < 3; ++c) colors[v * components + c] = multiply ? inst.colors[v][int(c)] * w[v] : w[v];
      if (alpha) colors[v * components + 3] = inst.colors[v].a;
    }
    attributes["COLOR_0"] = gltf::add_float_accessor(doc, colors, w.size(), alpha ? "VEC4" : "VEC3");
  }
}

Status write_gltf(const std::filesystem::path& input, const scene::Scene& scene, const Bake& bake, Into into,
                  const std::filesystem::path& output) {
  auto doc = gltf::read_document(input);
  if (!doc) return doc.error();
  add_to_document(*doc, scene, bake, into);
  auto written = gltf::write_document(*doc, output);
  if (!written) return written.error();
  return success();
}

}  // namespace matbake::ao
