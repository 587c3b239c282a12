#include "placements.hpp"

#include <map>
#include <set>

namespace matbake::gltf {

std::vector<int> split_placements(Document& doc, const scene::Scene& scene, const std::vector<int>& materials,
                                  const std::vector<int>& nodes) {
  Json& json = doc.json;
  std::vector<int> into = materials;
  std::set<int> split_nodes(nodes.begin(), nodes.end());
  split_nodes.erase(-1);
  if (split_nodes.empty()) return into;
  std::map<int, int> owner_of_mesh, mesh_of_node;
  for (const scene::Instance& inst : scene.instances) {  // scene order: the first placement keeps the mesh
    if (!split_nodes.contains(inst.node) || mesh_of_node.contains(inst.node)) continue;
    const int mesh = json["nodes"][std::size_t(inst.node)]["mesh"].get<int>();
    if (owner_of_mesh.try_emplace(mesh, inst.node).second) {
      mesh_of_node[inst.node] = mesh;
      continue;
    }
    json["meshes"].push_back(json["meshes"][std::size_t(mesh)]);
    mesh_of_node[inst.node] = int(json["meshes"].size()) - 1;
    json["nodes"][std::size_t(inst.node)]["mesh"] = mesh_of_node[inst.node];
  }
  std::set<int> kept;
  for (std::size_t t = 0; t < into.size(); ++t) {
    const int m = materials[t], node = nodes[t];
    if (node < 0 || kept.insert(m).second) continue;
    Json copy = json["materials"][std::size_t(m)];
    const std::string node_name = name_in(json["nodes"][std::size_t(node)], "node " + std::to_string(node));
    copy["name"] = name_in(copy, "material " + std::to_string(m)) + " (" + node_name + ")";
    json["materials"].push_back(std::move(copy));
    into[t] = int(json["materials"].size()) - 1;
    for (Json& primitive : json["meshes"][std::size_t(mesh_of_node.at(node))]["primitives"]) {
      if (integer_in<int>(primitive, "material", -1, -1) == m) primitive["material"] = into[t];
    }
  }
  return into;
}

}  // namespace matbake::gltf
