#include "support/gltf_builder.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>

namespace matbake::test {

std::string base64(const std::vector<unsigned char>& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t(bytes[i]) << 16) | (i + 1 < bytes.size() ? std::uint32_t(bytes[i + 1]) << 8 : 0) |
                            (i + 2 < bytes.size() ? std::uint32_t(bytes[i + 2]) : 0);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

int GltfBuilder::add_floats(const std::vector<float>& values, const std::string& type, int components) {
  const std::size_t offset = bytes.size();
  bytes.resize(offset + values.size() * 4);
  std::memcpy(bytes.data() + offset, values.data(), values.size() * 4);
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * 4}});
  doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", 5126},
                              {"count", values.size() / std::size_t(components)}, {"type", type}});
  return int(doc["accessors"].size()) - 1;
}

int GltfBuilder::add_vec3(const std::vector<float>& xyz) {
  const int accessor = add_floats(xyz, "VEC3", 3);
  // POSITION accessors must carry their bounds (glTF 2.0, 3.6.2.4).
  float lo[3] = {xyz[0], xyz[1], xyz[2]}, hi[3] = {xyz[0], xyz[1], xyz[2]};
  for (std::size_t i = 0; i < xyz.size(); ++i) lo[i % 3] = std::min(lo[i % 3], xyz[i]), hi[i % 3] = std::max(hi[i % 3], xyz[i]);
  doc["accessors"][std::size_t(accessor)]["min"] = lo;
  doc["accessors"][std::size_t(accessor)]["max"] = hi;
  return accessor;
}

int GltfBuilder::add_indices(const std::vector<std::uint32_t>& indices) {
  const std::size_t offset = bytes.size();
  bytes.resize(offset + indices.size() * 4);
  std::memcpy(bytes.data() + offset, indices.data(), indices.size() * 4);
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", indices.size() * 4}});
  doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", 5125},
                              {"count", indices.size()}, {"type", "SCALAR"}});
  return int(doc["accessors"].size()) - 1;
}

int GltfBuilder::add_mesh(int positions, int indices, int mode, int normals) {
  nlohmann::json primitive = {{"attributes", {{"POSITION", positions}}}, {"mode", mode}};
  if (indices >= 0) primitive["indices"] = indices;
  if (normals >= 0) primitive["attributes"]["NORMAL"] = normals;
  doc["meshes"].push_back({{"primitives", {primitive}}});
  return int(doc["meshes"].size()) - 1;
}

int GltfBuilder::add_node(nlohmann::json node) {
  doc["nodes"].push_back(std::move(node));
  return int(doc["nodes"].size()) - 1;
}

void GltfBuilder::write(const std::filesystem::path& path, const std::vector<int>& scene_nodes) {
  nlohmann::json out = doc;
  if (!bytes.empty() && external_bin) {
    const std::string bin = path.stem().string() + ".bin";
    std::ofstream(path.parent_path() / bin, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out["buffers"] = {{{"byteLength", bytes.size()}, {"uri", bin}}};
  } else if (!bytes.empty()) {
    out["buffers"] = {{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}};
  }
  out["scenes"] = {{{"nodes", scene_nodes}}};
  out["scene"] = 0;
  std::ofstream(path) << out.dump(1);
}

void write_grey_mesh(const std::filesystem::path& path, const std::vector<glm::dvec3>& positions,
                     const std::vector<glm::dvec3>& normals, const std::vector<glm::vec2>& texcoords,
                     const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<glm::dvec3>& colors) {
  GltfBuilder b;
  std::vector<float> p, n, uv, rgb;
  std::vector<std::uint32_t> indices;
  for (const auto& v : positions) p.insert(p.end(), {float(v.x), float(v.y), float(v.z)});
  for (const auto& v : normals) n.insert(n.end(), {float(v.x), float(v.y), float(v.z)});
  for (const auto& v : texcoords) uv.insert(uv.end(), {v.x, v.y});
  for (const auto& c : colors) rgb.insert(rgb.end(), {float(c.r), float(c.g), float(c.b)});
  for (const auto& t : triangles) indices.insert(indices.end(), t.begin(), t.end());
  const int mesh = b.add_mesh(b.add_vec3(p), b.add_indices(indices), 4, n.empty() ? -1 : b.add_vec3(n));
  auto& primitive = b.doc["meshes"][std::size_t(mesh)]["primitives"][0];
  if (!uv.empty()) primitive["attributes"]["TEXCOORD_0"] = b.add_floats(uv, "VEC2", 2);
  if (!rgb.empty()) primitive["attributes"]["COLOR_0"] = b.add_floats(rgb, "VEC3", 3);
  primitive["material"] = 0;
  b.doc["materials"] = {{{"name", "grey"},
                         {"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.2, 0.2, 1}}, {"metallicFactor", 0}, {"roughnessFactor", 0.6}}}}};
  b.write(path, {b.add_node({{"mesh", mesh}})});
}

}  // namespace matbake::test
