#include "tangents.hpp"

#include "decode.hpp"

#include <cstring>
#include <map>
#include <tuple>

namespace matbake::gltf {
namespace {

// A corner's vertex with what it must carry: corners equal in all of it share a vertex.
struct CornerKey {
  std::uint32_t vertex;
  std::array<float, 4> tangent;
  std::array<float, 3> normal;
  bool operator<(const CornerKey& o) const {
    return std::tie(vertex, tangent, normal) < std::tie(o.vertex, o.tangent, o.normal);
  }
};

// Accessor `index`'s elements in the order `source` lists (element source[i] as element i), tightly
// packed but each 4-byte aligned (glTF's rule for vertex attributes); a new accessor of the same type.
Result<int> gathered(Document& doc, std::size_t index, const std::vector<std::uint32_t>& source) {
  auto bytes = accessor_bytes(doc, index);
  if (!bytes) return bytes.error();
  const std::size_t size = bytes->components * bytes->component_size, stride = (size + 3) / 4 * 4;
  std::vector<unsigned char> out(source.size() * stride, 0);
  for (std::size_t i = 0; i < source.size(); ++i) std::memcpy(&out[i * stride], bytes->first + source[i] * bytes->stride, size);
  const int view = add_view(doc, out, kArrayBuffer);
  if (stride != size) doc.json["bufferViews"][std::size_t(view)]["byteStride"] = stride;
  const Json& old = doc.json["accessors"][index];
  Json accessor = {{"bufferView", view}, {"componentType", bytes->component_type}, {"count", source.size()}, {"type", old["type"]}};
  if (bytes->normalized) accessor["normalized"] = true;
  for (const char* key : {"min", "max"}) {  // the vertices are those of the old accessor, some twice
    if (old.contains(key)) accessor[key] = old[key];
  }
  doc.json["accessors"].push_back(std::move(accessor));
  return int(doc.json["accessors"].size()) - 1;
}

// Every attribute of `attributes` (a primitive's, or a morph target's) gathered by `source`.
Status gather_all(Document& doc, Json& attributes, const std::vector<std::uint32_t>& source) {
  for (auto it = attributes.begin(); it != attributes.end(); ++it) {
    auto made = gathered(doc, size_in(attributes, it.key().c_str(), SIZE_MAX), source);
    if (!made) return made.error();
    it.value() = *made;
  }
  return success();
}

}  // namespace

Result<AddedTangents> add_tangents(Document& doc, const PrimitiveTangents& p) {
  // A Draco primitive changed is written uncompressed, as every primitive matbake changes.
  uncompress_draco_primitive(doc, std::size_t(p.mesh), std::size_t(p.primitive));
  for (const char* key : {"accessors", "bufferViews", "buffers"}) {  // present before references into the JSON are held
    if (!doc.json.contains(key)) doc.json[key] = Json::array();
  }
  Json& primitive = doc.json["meshes"][std::size_t(p.mesh)]["primitives"][std::size_t(p.primitive)];
  Json& attributes = primitive["attributes"];
  const bool has_normals = attributes.contains("NORMAL");
  auto positions = accessor_bytes(doc, size_in(attributes, "POSITION", SIZE_MAX));
  if (!positions) return positions.error();
  const std::size_t vertices = positions->count;

  // Each corner's vertex: its own number the first time, a copy after the others when it must differ.
  std::map<CornerKey, std::uint32_t> vertex_of;
  std::vector<bool> claimed(vertices, false);
  std::vector<std::uint32_t> source(vertices), corners;
  for (std::uint32_t v = 0; v < vertices; ++v) source[v] = v;
  std::vector<glm::vec4> tangents(vertices, glm::vec4(1, 0, 0, 1));
  std::vector<glm::vec3> normals(vertices, glm::vec3(0, 0, 1));
  for (std::size_t c = 0; c < 3 * p.triangles.size(); ++c) {
    const std::uint32_t v = p.triangles[c / 3][c % 3];
    const glm::vec4& t = p.tangents[c];
    const glm::vec3 n = has_normals ? glm::vec3(0) : p.normals[c];
    const CornerKey key{v, {t.x, t.y, t.z, t.w}, {n.x, n.y, n.z}};
    auto [it, added] = vertex_of.try_emplace(key, v);
    if (added && claimed[v]) {
      it->second = std::uint32_t(source.size());
      source.push_back(v);
      tangents.push_back(t), normals.push_back(n);
    } else if (added) {
      claimed[v] = true;
      tangents[v] = t, normals[v] = n;
    }
    corners.push_back(it->second);
  }
  const std::size_t added = source.size() - vertices;
  if (added > 0) {
    if (Status s = gather_all(doc, attributes, source); !s) return s.error();
    if (primitive.contains("targets")) {
      for (Json& target : primitive["targets"]) {
        if (Status s = gather_all(doc, target, source); !s) return s.error();
      }
    }
    primitive["indices"] = add_index_accessor(doc, corners, source.size());
    primitive.erase("mode");  // now a triangle list
  }
  std::vector<float> tangent_values, normal_values;
  for (const glm::vec4& t : tangents) tangent_values.insert(tangent_values.end(), {t.x, t.y, t.z, t.w});
  for (const glm::vec3& n : normals) normal_values.insert(normal_values.end(), {n.x, n.y, n.z});
  attributes["TANGENT"] = add_float_accessor(doc, tangent_values, source.size(), "VEC4");
  if (!has_normals) attributes["NORMAL"] = add_float_accessor(doc, normal_values, source.size(), "VEC3");
  return AddedTangents{added, std::move(corners)};
}

}  // namespace matbake::gltf
