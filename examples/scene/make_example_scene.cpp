// Writes the bundled example scene, examples/showroom.gltf + showroom.bin (committed; a test checks
// that this program still writes exactly those bytes): a floor, three crates placed from one mesh,
// gold trim on two of them, two wooden pillars from one mesh and two glass panes from one mesh,
// with the five materials the manifest gives textures (examples/showroom.toml).
//   make_example_scene OUT_FOLDER
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

namespace {

struct Vertex {
  float p[3], n[3], uv[2];
};

struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<std::uint16_t> indices;

  // A quad from corner `o` along edges `u` and `v` (normal u × v), mapped onto the UV rectangle
  // from (u0, v0) to (u1, v1) (texture v downwards: the quad's far edge along v at v0).
  void quad(const float o[3], const float u[3], const float v[3], float u0 = 0, float v0 = 0, float u1 = 1, float v1 = 1) {
    const float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const auto base = std::uint16_t(vertices.size());
    for (int corner = 0; corner < 4; ++corner) {
      const float a = corner == 1 || corner == 2 ? 1.f : 0.f, b = corner >= 2 ? 1.f : 0.f;
      Vertex vx{};
      for (int i = 0; i < 3; ++i) {
        vx.p[i] = o[i] + a * u[i] + b * v[i];
        vx.n[i] = n[i] / len;
      }
      vx.uv[0] = u0 + a * (u1 - u0);
      vx.uv[1] = v0 + (1 - b) * (v1 - v0);
      vertices.push_back(vx);
    }
    for (int i : {0, 1, 2, 0, 2, 3}) indices.push_back(std::uint16_t(base + i));
  }
};

// Every surface of a mesh has UVs of its own (no two faces share texels), so that occlusion can be
// baked into its textures (`ao = { texture = ... }`); a gutter of 1/32 keeps the islands apart.
constexpr float kGutter = 1.0f / 32;

// An axis-aligned box centred on x and z, standing on y = y0; its six faces in a 3 × 2 UV grid.
Mesh box(float w, float h, float d, float y0 = 0) {
  Mesh m;
  const float x = w / 2, z = d / 2;
  int cell = 0;
  auto face = [&](float ox, float oy, float oz, float ux, float uy, float uz, float vx, float vy, float vz) {
    const float o[3] = {ox, oy, oz}, u[3] = {ux, uy, uz}, v[3] = {vx, vy, vz};
    const float column = float(cell % 3), row = float(cell / 3);
    m.quad(o, u, v, column / 3 + kGutter, row / 2 + kGutter, (column + 1) / 3 - kGutter, (row + 1) / 2 - kGutter);
    ++cell;
  };
  face(-x, y0, z, w, 0, 0, 0, h, 0);        // +z
  face(x, y0, -z, -w, 0, 0, 0, h, 0);       // −z
  face(x, y0, z, 0, 0, -d, 0, h, 0);        // +x
  face(-x, y0, -z, 0, 0, d, 0, h, 0);       // −x
  face(-x, y0 + h, z, w, 0, 0, 0, 0, -d);   // top
  face(-x, y0, -z, w, 0, 0, 0, 0, d);       // bottom
  return m;
}

// A cylinder of `segments` flat sides standing on y = 0, with a top cap: the sides one strip along
// the top of the UV square, the cap a disc below it.
Mesh cylinder(float r, float h, int segments) {
  Mesh m;
  for (int s = 0; s < segments; ++s) {
    const double a0 = 2 * std::numbers::pi * s / segments, a1 = 2 * std::numbers::pi * (s + 1) / segments;
    const float o[3] = {r * float(std::cos(a0)), 0, r * float(std::sin(a0))};
    const float u[3] = {r * float(std::cos(a1) - std::cos(a0)), 0, r * float(std::sin(a1) - std::sin(a0))};
    const float v[3] = {0, h, 0};
    // Wound so that the normal (v × u here, after swapping) points outwards.
    m.quad(o, v, u, kGutter, float(s + 1) / float(segments), 0.7f, float(s) / float(segments));  // seamless strip
  }
  const auto centre = std::uint16_t(m.vertices.size());
  constexpr float kCapU = 0.85f, kCapV = 0.5f, kCapRadius = 0.15f - kGutter;
  m.vertices.push_back({{0, h, 0}, {0, 1, 0}, {kCapU, kCapV}});
  for (int s = 0; s <= segments; ++s) {
    const double a = 2 * std::numbers::pi * s / segments;
    m.vertices.push_back({{r * float(std::cos(a)), h, r * float(std::sin(a))},
                          {0, 1, 0},
                          {kCapU + kCapRadius * float(std::cos(a)), kCapV + kCapRadius * float(std::sin(a))}});
  }
  for (int s = 0; s < segments; ++s) {
    for (int i : {0, s + 2, s + 1}) m.indices.push_back(std::uint16_t(centre + i));
  }
  return m;
}

struct Writer {
  std::vector<unsigned char> bin;
  nlohmann::ordered_json gltf;

  int view(const void* data, std::size_t bytes, int target) {
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t offset = bin.size();
    bin.insert(bin.end(), static_cast<const unsigned char*>(data), static_cast<const unsigned char*>(data) + bytes);
    gltf["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
    return int(gltf["bufferViews"].size()) - 1;
  }

  int accessor(int view_index, std::size_t offset, int component, std::size_t count, const char* type) {
    nlohmann::ordered_json a = {{"bufferView", view_index}, {"byteOffset", offset}, {"componentType", component},
                                {"count", count}, {"type", type}};
    gltf["accessors"].push_back(a);
    return int(gltf["accessors"].size()) - 1;
  }

  int mesh(const std::string& name, const Mesh& m, int material) {
    const int vertices = view(m.vertices.data(), m.vertices.size() * sizeof(Vertex), 34962);
    gltf["bufferViews"].back()["byteStride"] = sizeof(Vertex);
    const int indices = view(m.indices.data(), m.indices.size() * sizeof(std::uint16_t), 34963);
    const int position = accessor(vertices, 0, 5126, m.vertices.size(), "VEC3");
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (const Vertex& v : m.vertices) {
      for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], v.p[i]), hi[i] = std::max(hi[i], v.p[i]);
    }
    gltf["accessors"][std::size_t(position)]["min"] = {lo[0], lo[1], lo[2]};
    gltf["accessors"][std::size_t(position)]["max"] = {hi[0], hi[1], hi[2]};
    const int normal = accessor(vertices, 12, 5126, m.vertices.size(), "VEC3");
    const int uv = accessor(vertices, 24, 5126, m.vertices.size(), "VEC2");
    const int index = accessor(indices, 0, 5123, m.indices.size(), "SCALAR");
    gltf["meshes"].push_back(
        {{"name", name},
         {"primitives",
          {{{"attributes", {{"POSITION", position}, {"NORMAL", normal}, {"TEXCOORD_0", uv}}},
            {"indices", index},
            {"material", material}}}}});
    return int(gltf["meshes"].size()) - 1;
  }

  void node(const std::string& name, int mesh_index, std::vector<float> translation, float yaw_degrees = 0,
            float scale = 1) {
    const double half = yaw_degrees * std::numbers::pi / 360;
    nlohmann::ordered_json n = {{"name", name}, {"mesh", mesh_index}, {"translation", translation}};
    if (yaw_degrees != 0) n["rotation"] = {0.0, float(std::sin(half)), 0.0, float(std::cos(half))};
    if (scale != 1) n["scale"] = {scale, scale, scale};
    gltf["nodes"].push_back(n);
    gltf["scenes"][0]["nodes"].push_back(int(gltf["nodes"].size()) - 1);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_example_scene OUT_FOLDER\n");
    return 2;
  }
  const std::filesystem::path folder = argv[1];
  Writer w;
  w.gltf["asset"] = {{"version", "2.0"}, {"generator", "matbake examples/scene/make_example_scene"}};
  w.gltf["scene"] = 0;
  w.gltf["scenes"] = {{{"name", "showroom"}, {"nodes", nlohmann::ordered_json::array()}}};
  // Placeholder factors (a viewer shows something before the build): `matbake build` replaces
  // each material with its manifest entry's textures.
  const auto material = [&](const char* name, std::vector<float> base, float metallic, float roughness) {
    w.gltf["materials"].push_back({{"name", name},
                                   {"pbrMetallicRoughness",
                                    {{"baseColorFactor", base}, {"metallicFactor", metallic}, {"roughnessFactor", roughness}}}});
    return int(w.gltf["materials"].size()) - 1;
  };
  const int painted_metal = material("painted_metal", {0.03f, 0.08f, 0.17f, 1}, 0, 0.5f);
  const int gold_trim = material("gold_trim", {1, 0.57f, 0.1f, 1}, 1, 0.3f);
  const int wood = material("wood", {0.2f, 0.08f, 0.03f, 1}, 0, 0.6f);
  const int rubber = material("rubber", {0.03f, 0.03f, 0.03f, 1}, 0, 0.8f);
  const int glass = material("glass", {0.3f, 0.5f, 0.6f, 0.6f}, 0, 0.05f);
  w.gltf["materials"][std::size_t(glass)]["doubleSided"] = true;

  Mesh floor;
  {
    const float o[3] = {-4, 0, 4}, u[3] = {8, 0, 0}, v[3] = {0, 0, -8};
    floor.quad(o, u, v);
  }
  Mesh pane;
  {
    const float o[3] = {-0.6f, 0, 0}, u[3] = {1.2f, 0, 0}, v[3] = {0, 1.6f, 0};
    pane.quad(o, u, v);
  }
  const int floor_mesh = w.mesh("floor", floor, rubber);
  const int crate = w.mesh("crate", box(1, 1, 1), painted_metal);
  const int trim = w.mesh("trim", box(1.04f, 0.08f, 1.04f, 1.0f), gold_trim);
  const int pillar = w.mesh("pillar", cylinder(0.25f, 2.5f, 16), wood);
  const int pane_mesh = w.mesh("pane", pane, glass);

  w.node("floor", floor_mesh, {0, 0, 0});
  w.node("crate 1", crate, {-1.5f, 0, -0.5f});
  w.node("crate 2", crate, {0, 0, -1}, 30);
  w.node("crate 3", crate, {-1.5f, 1.08f, -0.5f}, 15, 0.8f);  // stacked on crate 1, on its trim
  w.node("trim 1", trim, {-1.5f, 0, -0.5f});
  w.node("trim 2", trim, {0, 0, -1}, 30);
  w.node("pillar left", pillar, {-3, 0, -3});
  w.node("pillar right", pillar, {3, 0, -3});
  w.node("pane 1", pane_mesh, {1.8f, 0, 0.5f}, -20);
  w.node("pane 2", pane_mesh, {-2.6f, 0, 1}, 35);

  w.gltf["buffers"] = {{{"uri", "showroom.bin"}, {"byteLength", w.bin.size()}}};
  std::ofstream bin(folder / "showroom.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(w.bin.data()), std::streamsize(w.bin.size()));
  std::ofstream text(folder / "showroom.gltf", std::ios::binary);
  text << w.gltf.dump(1) << "\n";
  if (!bin || !text) {
    std::fprintf(stderr, "make_example_scene: cannot write in %s\n", folder.c_str());
    return 1;
  }
  return 0;
}
