// A large scene for the scene benchmarks (scripts/bench-scene.sh): an N×N-vertex terrain grid with
// normals and texture coordinates, 2(N−1)² triangles (uint32 indices), one material, written as
// OUT.glb and OUT.gltf (+ OUT.bin). N = 1000: 1 M vertices, 2 M triangles.
// Usage: make_big_scene OUT_STEM [N]
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

template <class T>
void append(std::string& bytes, const std::vector<T>& values) {
  const std::size_t at = bytes.size();
  bytes.resize(at + values.size() * sizeof(T));
  std::memcpy(bytes.data() + at, values.data(), values.size() * sizeof(T));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: make_big_scene OUT_STEM [N]\n";
    return 2;
  }
  const std::string stem = argv[1];
  const int n = argc > 2 ? std::stoi(argv[2]) : 1000;
  std::vector<float> positions, normals, uvs;
  std::vector<std::uint32_t> indices;
  const auto height = [&](double x, double y) { return 0.05 * std::sin(7 * x) * std::cos(5 * y) + 0.02 * std::sin(31 * x + 17 * y); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = double(i) / (n - 1), y = double(j) / (n - 1), e = 1e-4;
      positions.insert(positions.end(), {float(x), float(height(x, y)), float(y)});
      const double dx = (height(x + e, y) - height(x - e, y)) / (2 * e), dy = (height(x, y + e) - height(x, y - e)) / (2 * e);
      const double length = std::sqrt(dx * dx + 1 + dy * dy);
      normals.insert(normals.end(), {float(-dx / length), float(1 / length), float(-dy / length)});
      uvs.insert(uvs.end(), {float(x), float(y)});
    }
  }
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const std::uint32_t a = std::uint32_t(j * n + i), b = a + 1, c = a + std::uint32_t(n), d = c + 1;
      indices.insert(indices.end(), {a, c, b, b, c, d});  // facing +y
    }
  }
  std::string bin;
  append(bin, positions);
  append(bin, normals);
  append(bin, uvs);
  append(bin, indices);
  const std::size_t vertices = positions.size() / 3;
  const std::size_t p_bytes = positions.size() * 4, n_bytes = normals.size() * 4, t_bytes = uvs.size() * 4;
  nlohmann::ordered_json doc = {
      {"asset", {{"version", "2.0"}, {"generator", "matbake bench/make_big_scene"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"materials", {{{"name", "ground"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.4, 0.35, 0.3, 1.0}}}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}}, {"indices", 3}, {"material", 0}}}}}}},
      {"buffers", {{{"byteLength", bin.size()}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", p_bytes}, {"target", 34962}},
                       {{"buffer", 0}, {"byteOffset", p_bytes}, {"byteLength", n_bytes}, {"target", 34962}},
                       {{"buffer", 0}, {"byteOffset", p_bytes + n_bytes}, {"byteLength", t_bytes}, {"target", 34962}},
                       {{"buffer", 0}, {"byteOffset", p_bytes + n_bytes + t_bytes}, {"byteLength", indices.size() * 4}, {"target", 34963}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", vertices}, {"type", "VEC3"},
                      {"min", {0.0, -0.07, 0.0}}, {"max", {1.0, 0.07, 1.0}}},
                     {{"bufferView", 1}, {"componentType", 5126}, {"count", vertices}, {"type", "VEC3"}},
                     {{"bufferView", 2}, {"componentType", 5126}, {"count", vertices}, {"type", "VEC2"}},
                     {{"bufferView", 3}, {"componentType", 5125}, {"count", indices.size()}, {"type", "SCALAR"}}}}};
  // The min/max of POSITION as the data has them (the validator checks them).
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (std::size_t v = 0; v < vertices; ++v) {
    for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], positions[v * 3 + std::size_t(c)]), hi[c] = std::max(hi[c], positions[v * 3 + std::size_t(c)]);
  }
  doc["accessors"][0]["min"] = {lo[0], lo[1], lo[2]};
  doc["accessors"][0]["max"] = {hi[0], hi[1], hi[2]};

  {  // .gltf + .bin
    nlohmann::ordered_json gltf = doc;
    const std::string bin_name = stem.substr(stem.find_last_of('/') + 1) + ".bin";
    gltf["buffers"][0]["uri"] = bin_name;
    std::ofstream(stem + ".gltf") << gltf.dump(1) << "\n";
    std::ofstream(stem + ".bin", std::ios::binary) << bin;
  }
  {  // .glb
    std::string json = doc.dump();
    json.resize((json.size() + 3) / 4 * 4, ' ');
    bin.resize((bin.size() + 3) / 4 * 4, '\0');
    const std::uint32_t total = std::uint32_t(12 + 8 + json.size() + 8 + bin.size());
    std::ofstream out(stem + ".glb", std::ios::binary);
    const auto u32 = [&](std::uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
    out.write("glTF", 4);
    u32(2);
    u32(total);
    u32(std::uint32_t(json.size()));
    out.write("JSON", 4);
    out << json;
    u32(std::uint32_t(bin.size()));
    out.write("BIN\0", 4);
    out << bin;
  }
  std::cout << stem << ".glb and .gltf: " << vertices << " vertices, " << indices.size() / 3 << " triangles\n";
  return 0;
}
