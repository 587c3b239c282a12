#include "join.hpp"

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include "../scene/from_document.hpp"

namespace matbake::delivery {
namespace {

using gltf::array_in;
using gltf::Json;

using gltf::kTriangles;

// A primitive placed once, by a node that nothing moves: joined in world space.
struct Placed {
  std::size_t mesh = 0, primitive = 0;
  glm::dmat4 world{1.0};
};

// What primitives must share to become one: their material and their attributes with their widths.
using JoinKey = std::pair<int, std::vector<std::pair<std::string, std::size_t>>>;

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// Whether a primitive can be read into floats and merged: triangles, no morph targets, no
// extension (Draco is decoded on reading and dropped with the primitive), no skinning attributes. A
// quantized attribute's integers become the floats they stand for (its node's dequantizing transform
// goes into world space with the rest); a custom integer attribute (an ID) keeps its type where it is.
bool joinable(const gltf::Document& doc, const Json& primitive) {
  if (!primitive.is_object() || primitive.contains("targets") || gltf::integer_in<int>(primitive, "mode", kTriangles, -1) != kTriangles) {
    return false;
  }
  if (primitive.contains("extensions")) {
    for (const auto& [name, value] : primitive["extensions"].items()) {
      if (name != "KHR_draco_mesh_compression") return false;
    }
  }
  const Json& attributes = primitive.value("attributes", Json::object());
  if (!attributes.is_object() || !attributes.contains("POSITION")) return false;
  for (const auto& [name, index] : attributes.items()) {
    if (starts_with(name, "JOINTS_") || starts_with(name, "WEIGHTS_")) return false;
    auto bytes = gltf::accessor_bytes(doc, gltf::size_in(attributes, name.c_str(), SIZE_MAX));
    if (!bytes || (starts_with(name, "_") && bytes->component_type != gltf::kFloat && !bytes->normalized)) return false;
  }
  return true;
}

// The nodes an animation moves, skins bend or KHR_animation_pointer may reach: kept with what is below them.
std::set<std::size_t> moving_nodes(const Json& json) {
  std::set<std::size_t> moving;
  for (const Json& animation : array_in(json, "animations")) {
    for (const Json& channel : array_in(animation, "channels")) {
      if (channel.contains("target")) moving.insert(gltf::size_in(channel["target"], "node", SIZE_MAX));
    }
  }
  for (const Json& skin : array_in(json, "skins")) {
    for (const Json& joint : array_in(skin, "joints")) {
      if (joint.is_number_unsigned()) moving.insert(joint.get<std::size_t>());
    }
  }
  return moving;
}

// Every node of the scene whose mesh can move into world space, with its world transform.
std::vector<std::pair<std::size_t, glm::dmat4>> static_placements(const gltf::Document& doc, const Json& scene) {
  const Json& nodes = array_in(doc.json, "nodes");
  const Json& meshes = array_in(doc.json, "meshes");
  std::map<std::size_t, int> placements;  // mesh → nodes placing it
  for (const Json& node : nodes) {
    if (node.contains("mesh")) ++placements[gltf::size_in(node, "mesh", SIZE_MAX)];
  }
  // Meshes whose primitives share their vertices are instances too (MetalRoughSpheresNoTextures: 98
  // meshes over one sphere's accessors): joined, each would become a copy.
  std::map<std::size_t, int> position_uses;  // POSITION accessor → primitives reading it
  for (const Json& mesh : meshes) {
    for (const Json& p : array_in(mesh, "primitives")) {
      if (p.is_object() && p.contains("attributes")) ++position_uses[gltf::size_in(p["attributes"], "POSITION", SIZE_MAX)];
    }
  }
  const auto own_vertices = [&](const Json& p) { return position_uses[gltf::size_in(p["attributes"], "POSITION", SIZE_MAX)] == 1; };
  const std::set<std::size_t> moving = moving_nodes(doc.json);
  std::vector<std::pair<std::size_t, glm::dmat4>> out;
  std::vector<std::pair<std::size_t, glm::dmat4>> stack;
  for (const Json& root : array_in(scene, "nodes")) stack.emplace_back(root.get<std::size_t>(), glm::dmat4(1.0));
  std::set<std::size_t> seen;
  while (!stack.empty()) {
    const auto [n, parent] = stack.back();
    stack.pop_back();
    if (n >= nodes.size() || moving.contains(n) || !seen.insert(n).second) continue;  // below a moving node: kept
    const Json& node = nodes[n];
    const glm::dmat4 world = parent * scene::local_matrix(node);
    for (const Json& child : array_in(node, "children")) stack.emplace_back(child.get<std::size_t>(), world);
    const std::size_t m = gltf::size_in(node, "mesh", SIZE_MAX);
    if (m >= meshes.size() || placements[m] != 1 || node.contains("skin") || node.contains("weights") ||
        node.contains("extensions") || meshes[m].contains("weights") || !std::isnormal(glm::determinant(glm::dmat3(world)))) {
      continue;
    }
    const Json& primitives = array_in(meshes[m], "primitives");
    if (!primitives.empty() && std::all_of(primitives.begin(), primitives.end(), [&](const Json& p) { return joinable(doc, p) && own_vertices(p); })) {
      out.emplace_back(n, world);
    }
  }
  return out;
}

// One joined primitive's streams, as floats, and its triangles.
struct Joined {
  std::map<std::string, std::vector<float>> streams;
  std::map<std::string, std::size_t> widths;
  std::vector<std::uint32_t> indices;
  std::size_t vertices = 0;
};

// Appends primitive `placed` to `into`: positions, normals and tangents into world space (a mirroring
// transform flips the triangles' winding and the tangents' handedness), the rest as read.
Status append(const gltf::Document& doc, const Placed& placed, Joined& into) {
  const Json& primitive = doc.json["meshes"][placed.mesh]["primitives"][placed.primitive];
  const std::string where = "/meshes/" + std::to_string(placed.mesh) + "/primitives/" + std::to_string(placed.primitive);
  const glm::dmat3 linear(placed.world), normal_matrix = glm::inverseTranspose(linear);
  const bool mirrored = glm::determinant(linear) < 0;
  std::size_t vertices = 0;
  for (const auto& [name, index] : primitive["attributes"].items()) {
    auto a = gltf::accessor_bytes(doc, gltf::size_in(primitive["attributes"], name.c_str(), SIZE_MAX));
    if (!a) return a.error();
    if (name == "POSITION") vertices = a->count;
    into.widths[name] = a->components;
    std::vector<float>& out = into.streams[name];
    for (std::size_t i = 0; i < a->count; ++i) {
      double v[4] = {0, 0, 0, 0};
      for (std::size_t c = 0; c < a->components && c < 4; ++c) {
        v[c] = gltf::component_value(a->first + i * a->stride + c * a->component_size, a->component_type, a->normalized);
      }
      glm::dvec3 xyz(v[0], v[1], v[2]);
      if (name == "POSITION") xyz = glm::dvec3(placed.world * glm::dvec4(xyz, 1.0));
      else if (name == "NORMAL" || name == "TANGENT") {
        xyz = name == "NORMAL" ? normal_matrix * xyz : linear * xyz;
        const double length = glm::length(xyz);
        if (length > 0) xyz /= length;
        if (name == "TANGENT" && mirrored) v[3] = -v[3];
      }
      if (name == "POSITION" || name == "NORMAL" || name == "TANGENT") v[0] = xyz.x, v[1] = xyz.y, v[2] = xyz.z;
      for (std::size_t c = 0; c < a->components; ++c) out.push_back(float(v[c]));
    }
  }
  for (const auto& [name, stream] : into.streams) {
    if (stream.size() != (into.vertices + vertices) * into.widths[name]) {
      return Error{doc.file, where + ": " + name + " and POSITION counts differ"};
    }
  }
  std::vector<std::uint32_t> order(vertices);
  std::iota(order.begin(), order.end(), 0u);
  if (primitive.contains("indices")) {
    auto idx = gltf::accessor_bytes(doc, gltf::size_in(primitive, "indices", SIZE_MAX));
    if (!idx) return idx.error();
    order.resize(idx->count);
    for (std::size_t i = 0; i < idx->count; ++i) {
      order[i] = gltf::index_value(idx->first + i * idx->stride, idx->component_type);
      if (order[i] >= vertices) return Error{doc.file, where + ": index " + std::to_string(i) + " is past its vertices"};
    }
  }
  for (std::size_t t = 0; t + 2 < order.size(); t += 3) {  // an incomplete last triangle is dropped
    const std::uint32_t base = std::uint32_t(into.vertices);
    into.indices.insert(into.indices.end(), {base + order[t], base + order[t + (mirrored ? 2 : 1)], base + order[t + (mirrored ? 1 : 2)]});
  }
  into.vertices += vertices;
  return success();
}

const char* type_of(std::size_t components) {
  return components == 1 ? "SCALAR" : components == 2 ? "VEC2" : components == 3 ? "VEC3" : "VEC4";
}

// The joined primitive written: one float accessor per stream (POSITION with its bounds), 32-bit
// indices (the geometry pass narrows them).
Json write_primitive(gltf::Document& doc, const Joined& joined, int material) {
  Json attributes = Json::object();
  for (const auto& [name, stream] : joined.streams) {
    const std::size_t width = joined.widths.at(name);
    const int accessor = gltf::add_float_accessor(doc, stream, joined.vertices, type_of(width));
    if (name == "POSITION") {
      std::vector<float> lo(3, INFINITY), hi(3, -INFINITY);
      for (std::size_t i = 0; i < stream.size(); ++i) lo[i % 3] = std::min(lo[i % 3], stream[i]), hi[i % 3] = std::max(hi[i % 3], stream[i]);
      doc.json["accessors"][std::size_t(accessor)]["min"] = lo;
      doc.json["accessors"][std::size_t(accessor)]["max"] = hi;
    }
    attributes[name] = accessor;
  }
  const std::span bytes(reinterpret_cast<const unsigned char*>(joined.indices.data()), joined.indices.size() * sizeof(std::uint32_t));
  const int view = gltf::add_view(doc, bytes, gltf::kElementArrayBuffer);
  doc.json["accessors"].push_back({{"bufferView", view}, {"componentType", gltf::kUnsignedInt}, {"count", joined.indices.size()}, {"type", "SCALAR"}});
  Json primitive = {{"attributes", attributes}, {"indices", int(doc.json["accessors"].size()) - 1}};
  if (material >= 0) primitive["material"] = material;
  return primitive;
}

// Nodes left with nothing (no mesh, child, camera, skin or extension) are removed, and every node
// index renumbered (scenes, children, skins, animation targets).
void remove_empty_nodes(Json& json) {
  Json& nodes = json["nodes"];
  std::vector<bool> keep(nodes.size(), true);
  const std::set<std::size_t> moving = moving_nodes(json);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t n = 0; n < nodes.size(); ++n) {
      const Json& node = nodes[n];
      const bool has_child = std::any_of(array_in(node, "children").begin(), array_in(node, "children").end(),
                                         [&](const Json& c) { return c.get<std::size_t>() < keep.size() && keep[c.get<std::size_t>()]; });
      const bool empty = !has_child && !node.contains("mesh") && !node.contains("camera") && !node.contains("skin") &&
                         !node.contains("extensions") && !moving.contains(n);
      if (keep[n] && empty) keep[n] = false, changed = true;
    }
  }
  std::vector<int> renumbered(nodes.size(), -1);
  int next = 0;
  for (std::size_t n = 0; n < nodes.size(); ++n) renumbered[n] = keep[n] ? next++ : -1;
  const auto remap = [&](Json& list) {
    Json out = Json::array();
    for (const Json& n : list) {
      if (n.get<std::size_t>() < renumbered.size() && renumbered[n.get<std::size_t>()] >= 0) out.push_back(renumbered[n.get<std::size_t>()]);
    }
    list = out;
  };
  Json kept = Json::array();
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    if (!keep[n]) continue;
    Json node = nodes[n];
    if (node.contains("children")) {
      remap(node["children"]);
      if (node["children"].empty()) node.erase("children");
    }
    kept.push_back(std::move(node));
  }
  nodes = std::move(kept);
  for (Json& scene : json["scenes"]) {
    if (scene.contains("nodes")) remap(scene["nodes"]);
  }
  // Skin joints and animated nodes are never removed (moving_nodes), so their new numbers exist.
  if (json.contains("skins")) {
    for (Json& skin : json["skins"]) {
      if (skin.contains("joints")) remap(skin["joints"]);
      if (skin.contains("skeleton")) skin["skeleton"] = renumbered[skin["skeleton"].get<std::size_t>()];
    }
  }
  if (json.contains("animations")) {
    for (Json& animation : json["animations"]) {
      for (Json& channel : animation["channels"]) {
        if (channel.contains("target") && channel["target"].contains("node")) {
          channel["target"]["node"] = renumbered[channel["target"]["node"].get<std::size_t>()];
        }
      }
    }
  }
}

}  // namespace

Result<std::vector<std::string>> join_meshes(gltf::Document& doc) {
  const Json& scenes = array_in(doc.json, "scenes");
  if (scenes.size() != 1) return std::vector<std::string>{"meshes not joined: the file has " + std::to_string(scenes.size()) + " scenes"};
  const Json& used = array_in(doc.json, "extensionsUsed");
  if (std::find(used.begin(), used.end(), "KHR_animation_pointer") != used.end()) {
    return std::vector<std::string>{"meshes not joined: KHR_animation_pointer may animate any node"};
  }
  const auto placements = static_placements(doc, scenes[0]);
  // One mesh on a root node gains nothing; one below other nodes sheds them (BoxTextured: 3 → 1).
  const Json& roots = array_in(scenes[0], "nodes");
  if (placements.empty() ||
      (placements.size() == 1 && std::find(roots.begin(), roots.end(), placements[0].first) != roots.end())) {
    return std::vector<std::string>{};
  }
  std::map<JoinKey, std::vector<Placed>> groups;  // in material order, then layout
  for (const auto& [n, world] : placements) {
    const std::size_t m = gltf::size_in(doc.json["nodes"][n], "mesh", SIZE_MAX);
    const Json& primitives = doc.json["meshes"][m]["primitives"];
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      JoinKey key{gltf::integer_in<int>(primitives[p], "material", -1, -1), {}};
      for (const auto& [name, index] : primitives[p]["attributes"].items()) {
        key.second.emplace_back(name, gltf::components_of(doc.json["accessors"][index.get<std::size_t>()].value("type", "")));
      }
      std::sort(key.second.begin(), key.second.end());
      groups[key].push_back({m, p, world});
    }
  }
  Json mesh = {{"name", "joined"}, {"primitives", Json::array()}};
  for (const auto& [key, members] : groups) {
    Joined joined;
    for (const Placed& placed : members) {
      if (Status s = append(doc, placed, joined); !s) return s.error();
    }
    if (!joined.indices.empty()) mesh["primitives"].push_back(write_primitive(doc, joined, key.first));
  }
  for (const auto& [n, world] : placements) doc.json["nodes"][n].erase("mesh");
  doc.json["meshes"].push_back(std::move(mesh));
  doc.json["nodes"].push_back({{"name", "joined"}, {"mesh", doc.json["meshes"].size() - 1}});
  doc.json["scenes"][0]["nodes"].push_back(doc.json["nodes"].size() - 1);
  remove_empty_nodes(doc.json);
  return std::vector<std::string>{"joined (join_meshes): " + std::to_string(placements.size()) + " placed meshes into one mesh of " +
                                  std::to_string(doc.json["meshes"].back()["primitives"].size()) + " primitives in world space"};
}

}  // namespace matbake::delivery
