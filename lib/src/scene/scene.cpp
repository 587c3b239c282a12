#include "matbake/scene.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include "from_document.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <cstring>
#include <numeric>

namespace matbake::scene {
namespace fs = std::filesystem;
namespace {

using Json = gltf::Json;
using gltf::array_in;

constexpr int kTriangles = 4, kTriangleStrip = 5, kTriangleFan = 6;
using gltf::kUnsignedByte, gltf::kUnsignedShort, gltf::kUnsignedInt;

struct Reader {
  const gltf::Document& doc;

  Error error(const std::string& what) const { return Error{doc.file, what}; }

  // An accessor's elements (Draco, meshopt and sparse ones decoded when the document was read).
  Result<gltf::AccessorBytes> dense(int index) const {
    if (index < 0) return error("accessor " + std::to_string(index) + " does not exist");
    return gltf::accessor_bytes(doc, std::size_t(index));
  }

  // `components` floats per element (2 to 4): FLOAT, or integers (KHR_mesh_quantization), normalized
  // or not; each element handed to `use(element, const float*)`.
  template <class F>
  Status floats(int index, std::size_t components, F use) const {
    auto bytes = dense(index);
    if (!bytes) return bytes.error();
    if (bytes->components != components) {
      return error("accessor " + std::to_string(index) + " has " + std::to_string(bytes->components) + " components, expected " +
                   std::to_string(components));
    }
    float v[4] = {0, 0, 0, 1};
    for (std::size_t i = 0; i < bytes->count; ++i) {
      const unsigned char* element = bytes->first + i * bytes->stride;
      for (std::size_t c = 0; c < components; ++c) {
        v[c] = gltf::component_value(element + c * bytes->component_size, bytes->component_type, bytes->normalized);
      }
      use(i, v);
    }
    return success();
  }

  Result<std::vector<std::uint32_t>> indices(int index, std::size_t vertex_count) const {
    auto bytes = dense(index);
    if (!bytes) return bytes.error();
    const int type = bytes->component_type;
    if (bytes->components != 1 || (type != kUnsignedByte && type != kUnsignedShort && type != kUnsignedInt)) {
      return error("index accessor " + std::to_string(index) + " is not unsigned byte, short or int scalars");
    }
    std::vector<std::uint32_t> out(bytes->count);
    for (std::size_t i = 0; i < bytes->count; ++i) {
      const std::uint32_t v = gltf::index_value(bytes->first + i * bytes->stride, type);
      if (v >= vertex_count) {
        return error("index accessor " + std::to_string(index) + ": index " + std::to_string(v) + " at " + std::to_string(i) +
                     " is beyond the " + std::to_string(vertex_count) + " vertices");
      }
      out[i] = v;
    }
    return out;
  }
};

// glTF modes 4, 5, 6 to triangles (the spec's vertex order for strips and fans).
std::vector<std::array<std::uint32_t, 3>> triangles_of(const std::vector<std::uint32_t>& v, int mode) {
  std::vector<std::array<std::uint32_t, 3>> t;
  const std::size_t n = v.size();
  if (mode == kTriangles) {
    t.reserve(n / 3);
    for (std::size_t i = 0; i + 2 < n; i += 3) t.push_back({v[i], v[i + 1], v[i + 2]});
  } else if (mode == kTriangleStrip) {
    for (std::size_t i = 0; i + 2 < n; ++i) {
      t.push_back(i % 2 == 0 ? std::array{v[i], v[i + 1], v[i + 2]} : std::array{v[i], v[i + 2], v[i + 1]});
    }
  } else if (mode == kTriangleFan) {
    for (std::size_t i = 1; i + 1 < n; ++i) t.push_back({v[i], v[i + 1], v[0]});
  }
  return t;
}

// `count` numbers of json[key], or nothing when the key is absent.
std::optional<std::vector<double>> numbers(const Json& json, const char* key, std::size_t count) {
  if (!json.contains(key)) return std::nullopt;
  const Json& value = json[key];
  if (!value.is_array() || value.size() != count) return std::nullopt;
  std::vector<double> out;
  for (const Json& x : value) {
    if (!x.is_number()) return std::nullopt;
    out.push_back(x.get<double>());
  }
  return out;
}


const Json& object_in(const Json& json, const char* key) {
  static const Json empty = Json::object();
  return json.contains(key) && json[key].is_object() ? json[key] : empty;
}

int integer_in(const Json& json, const char* key, int absent) {
  if (!json.contains(key)) return absent;
  const Json& v = json[key];
  return v.is_number_integer() && v.get<long long>() >= 0 && v.get<long long>() <= INT32_MAX ? v.get<int>() : -2;
}

// One primitive placed by node `n`: its triangles, world positions, normals and colours.
Result<Instance> place_primitive(const Reader& read, const Json& primitive, int n, int mesh, int p, const glm::dmat4& world,
                                 const SceneContent& content) {
  const std::string where = "mesh " + std::to_string(mesh) + " primitive " + std::to_string(p);
  const Json& attributes = object_in(primitive, "attributes");
  if (!attributes.contains("POSITION")) return read.error(where + " has no POSITION");
  Instance inst;
  inst.node = n;
  inst.mesh = mesh;
  inst.primitive = p;
  inst.world = world;
  inst.material = integer_in(primitive, "material", -1);
  const int position = integer_in(attributes, "POSITION", -1);
  auto position_bytes = read.dense(position);
  if (!position_bytes) return position_bytes.error();
  const std::size_t vertices = position_bytes->count;
  inst.positions.reserve(vertices);
  std::size_t not_finite = vertices;
  Status s = read.floats(position, 3, [&](std::size_t v, const float* x) {
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2])) not_finite = std::min(not_finite, v);
    inst.positions.push_back(Vec3(world * glm::dvec4(x[0], x[1], x[2], 1.0)));
    if (content.object_space) inst.object.positions.emplace_back(x[0], x[1], x[2]);
  });
  if (!s) return s.error();
  if (not_finite < vertices) return read.error(where + ": POSITION of vertex " + std::to_string(not_finite) + " is not finite");

  std::vector<std::uint32_t> order;
  if (primitive.contains("indices")) {
    auto idx = read.indices(integer_in(primitive, "indices", -1), vertices);
    if (!idx) return idx.error();
    order = std::move(*idx);
  } else {
    order.resize(vertices);
    std::iota(order.begin(), order.end(), 0u);
  }
  inst.triangles = triangles_of(order, integer_in(primitive, "mode", kTriangles));
  if (glm::determinant(glm::dmat3(world)) < 0) {  // mirrored: keep the faces' facing
    for (auto& t : inst.triangles) std::swap(t[1], t[2]);
  }

  if (attributes.contains("NORMAL")) {
    const int normal = integer_in(attributes, "NORMAL", -1);
    auto bytes = read.dense(normal);
    if (!bytes) return bytes.error();
    if (bytes->count != vertices) return read.error(where + ": NORMAL and POSITION counts differ");
    const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(world));
    inst.normals.reserve(vertices);
    s = read.floats(normal, 3, [&](std::size_t, const float* x) {
      if (content.object_space) inst.object.normals.emplace_back(x[0], x[1], x[2]);
      const glm::dvec3 nv = normal_matrix * glm::dvec3(x[0], x[1], x[2]);
      const double length = glm::length(nv);
      inst.normals.push_back(length > 0 ? Vec3(nv / length) : Vec3(0));
    });
    if (!s) return s.error();
  }
  if (content.object_space && attributes.contains("TANGENT")) {
    const int tangent = integer_in(attributes, "TANGENT", -1);
    auto bytes = read.dense(tangent);
    if (!bytes) return bytes.error();
    if (bytes->count != vertices) return read.error(where + ": TANGENT and POSITION counts differ");
    inst.object.tangents.reserve(vertices);
    s = read.floats(tangent, 4, [&](std::size_t, const float* t) { inst.object.tangents.emplace_back(t[0], t[1], t[2], t[3]); });
    if (!s) return s.error();
  }
  if (attributes.contains("COLOR_0")) {
    const int color = integer_in(attributes, "COLOR_0", -1);
    auto bytes = read.dense(color);
    if (!bytes) return bytes.error();
    if (bytes->count != vertices) return read.error(where + ": COLOR_0 and POSITION counts differ");
    inst.colors_have_alpha = bytes->components == 4;
    inst.colors.reserve(vertices);
    s = read.floats(color, inst.colors_have_alpha ? 4 : 3,
                    [&](std::size_t, const float* c) { inst.colors.emplace_back(c[0], c[1], c[2], c[3]); });
    if (!s) return s.error();
  }
  if (content.texcoords) {
    // TEXCOORD_0, _1, ... as far as the file numbers them without a gap (as the spec requires).
    for (int set = 0;; ++set) {
      const std::string name = "TEXCOORD_" + std::to_string(set);
      if (!attributes.contains(name)) break;
      const int texcoord = integer_in(attributes, name.c_str(), -1);
      auto bytes = read.dense(texcoord);
      if (!bytes) return bytes.error();
      if (bytes->count != vertices) return read.error(where + ": " + name + " and POSITION counts differ");
      std::vector<glm::vec2>& uv = inst.texcoords.emplace_back();
      uv.reserve(vertices);
      s = read.floats(texcoord, 2, [&](std::size_t, const float* x) { uv.emplace_back(x[0], x[1]); });
      if (!s) return s.error();
    }
  }
  return inst;
}

}  // namespace

// The node's own transform: its matrix, else T · R · S.
glm::dmat4 local_matrix(const Json& node) {
  if (auto m = numbers(node, "matrix", 16)) return glm::make_mat4(m->data());  // column-major, as glm
  glm::dmat4 m(1.0);
  if (auto t = numbers(node, "translation", 3)) m = glm::translate(m, glm::dvec3((*t)[0], (*t)[1], (*t)[2]));
  if (auto r = numbers(node, "rotation", 4)) m *= glm::mat4_cast(glm::dquat((*r)[3], (*r)[0], (*r)[1], (*r)[2]));
  if (auto s = numbers(node, "scale", 3)) m = glm::scale(m, glm::dvec3((*s)[0], (*s)[1], (*s)[2]));
  return m;
}

float Scene::radius() const { return 0.5f * glm::length(bounds_max - bounds_min); }

Result<Scene> scene_from_document(const gltf::Document& doc, const SceneContent& content) {
  return guarded(doc.file, [&]() -> Result<Scene> {
    const Json& json = doc.json;
    const Reader read{doc};
    const Json& scenes = array_in(json, "scenes");
    const Json& nodes = array_in(json, "nodes");
    const Json& meshes = array_in(json, "meshes");
    Scene scene;
    int scene_index = integer_in(json, "scene", -1);
    if (scene_index == -1) {
      if (scenes.empty()) return read.error("no scene to bake");
      scene_index = 0;
      scene.notes.push_back("no default scene: using scene 0");
    }
    if (scene_index < 0 || std::size_t(scene_index) >= scenes.size()) return read.error("the default scene does not exist");

    // Depth first without recursion (a hostile file may chain a million nodes). glTF nodes form
    // strict trees: a node reached twice (a cycle, or two parents) is refused, which also bounds the
    // instances by the node count.
    std::vector<bool> reached(nodes.size(), false);
    std::vector<std::pair<int, glm::dmat4>> pending;  // node, its parent's world matrix
    const Json& roots = array_in(scenes[std::size_t(scene_index)], "nodes");
    for (auto root = roots.rbegin(); root != roots.rend(); ++root) {
      pending.emplace_back(root->is_number_integer() ? root->get<int>() : -1, glm::dmat4(1.0));
    }
    std::size_t ignored_primitives = 0;
    while (!pending.empty()) {
      const auto [n, parent] = pending.back();
      pending.pop_back();
      if (n < 0 || std::size_t(n) >= nodes.size()) return read.error("node " + std::to_string(n) + " does not exist");
      if (reached[std::size_t(n)]) {
        return read.error("node " + std::to_string(n) + " is its own ancestor or has two parents (glTF nodes form trees)");
      }
      reached[std::size_t(n)] = true;
      const Json& node = nodes[std::size_t(n)];
      const glm::dmat4 world = parent * local_matrix(node);
      if (node.contains("mesh")) {
        const int m = integer_in(node, "mesh", -1);
        if (m < 0 || std::size_t(m) >= meshes.size()) {
          return read.error("node " + std::to_string(n) + " refers to mesh " + node["mesh"].dump() + ", which does not exist");
        }
        const Json& primitives = array_in(meshes[std::size_t(m)], "primitives");
        for (std::size_t p = 0; p < primitives.size(); ++p) {
          const int mode = integer_in(primitives[p], "mode", kTriangles);
          if (mode != kTriangles && mode != kTriangleStrip && mode != kTriangleFan) {
            ++ignored_primitives;
            continue;
          }
          auto inst = place_primitive(read, primitives[p], n, m, int(p), world, content);
          if (!inst) return inst.error();
          inst->name = gltf::name_in(node, gltf::name_in(meshes[std::size_t(m)], ""));
          scene.instances.push_back(std::move(*inst));
        }
      }
      const Json& children = array_in(node, "children");
      for (auto child = children.rbegin(); child != children.rend(); ++child) {
        pending.emplace_back(child->is_number_integer() ? child->get<int>() : -1, world);
      }
    }
    if (ignored_primitives) {
      scene.notes.push_back(std::to_string(ignored_primitives) + " point or line primitives ignored");
    }
    std::size_t triangles = 0;
    bool first = true;
    for (const Instance& inst : scene.instances) {
      triangles += inst.triangles.size();
      for (const Vec3& p : inst.positions) {
        scene.bounds_min = first ? p : glm::min(scene.bounds_min, p);
        scene.bounds_max = first ? p : glm::max(scene.bounds_max, p);
        first = false;
      }
    }
    if (triangles == 0) return read.error("no triangles in the default scene");
    return scene;
  });
}

Result<Scene> load_scene(const fs::path& path, const SceneContent& content) {
  auto doc = gltf::read_document(path);
  if (!doc) return doc.error();
  return scene_from_document(*doc, content);
}

NormalResult vertex_normals(const std::vector<Vec3>& positions, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                            NormalWeighting weighting, const std::vector<Vec3>& original) {
  NormalResult result;
  std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0));
  glm::dvec3 total(0);
  for (const auto& t : triangles) {
    const glm::dvec3 p[3] = {positions[t[0]], positions[t[1]], positions[t[2]]};
    const glm::dvec3 cross = glm::cross(p[1] - p[0], p[2] - p[0]);
    const double twice_area = glm::length(cross);
    // Zero area, relative to the edge lengths (scale-free): skipped.
    const double scale = std::max({glm::length(p[1] - p[0]), glm::length(p[2] - p[0]), glm::length(p[2] - p[1])});
    if (!(twice_area > 1e-12 * scale * scale)) {
      ++result.degenerate_faces;
      continue;
    }
    const glm::dvec3 unit = cross / twice_area;
    total += cross;
    for (int k = 0; k < 3; ++k) {
      glm::dvec3 w = unit;
      if (weighting == NormalWeighting::area) w = cross;  // twice the area: a constant factor
      if (weighting == NormalWeighting::angle) {
        const glm::dvec3 a = glm::normalize(p[(k + 1) % 3] - p[k]), b = glm::normalize(p[(k + 2) % 3] - p[k]);
        w = unit * std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
      }
      sum[t[std::size_t(k)]] += w;
    }
  }
  const double total_length = glm::length(total);
  result.normals.resize(positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v) {
    const double length = glm::length(sum[v]);
    if (length > 0) {
      result.normals[v] = Vec3(sum[v] / length);
      continue;
    }
    ++result.fallbacks;
    if (v < original.size() && glm::length(original[v]) > 0) {
      result.normals[v] = original[v];
    } else {
      result.normals[v] = total_length > 0 ? Vec3(total / total_length) : Vec3(0, 0, 1);
    }
  }
  return result;
}

}  // namespace matbake::scene
