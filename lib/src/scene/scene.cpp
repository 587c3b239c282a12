#include "matbake/scene.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <tiny_gltf.h>

#include "../gltf/load_model.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstring>
#include <numeric>

namespace matbake::scene {
namespace fs = std::filesystem;
namespace {

// --- Accessors --------------------------------------------------------------------------------------
struct Reader {
  const tinygltf::Model& model;
  std::string file;

  Error error(const std::string& what) const { return Error{file, what}; }

  // The bytes of each element of an accessor, checked against its buffer view and buffer.
  Result<std::vector<const unsigned char*>> elements(int index, std::size_t element_size) const {
    if (index < 0 || std::size_t(index) >= model.accessors.size()) {
      return error("accessor " + std::to_string(index) + " does not exist");
    }
    const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
    const std::string name = "accessor " + std::to_string(index);
    if (a.sparse.isSparse) return error(name + " is sparse; matbake does not read sparse accessors");
    if (a.bufferView < 0 || std::size_t(a.bufferView) >= model.bufferViews.size()) {
      return error(name + " has no buffer view");
    }
    const tinygltf::BufferView& view = model.bufferViews[std::size_t(a.bufferView)];
    if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size()) {
      return error("buffer view " + std::to_string(a.bufferView) + " has no buffer");
    }
    const std::vector<unsigned char>& data = model.buffers[std::size_t(view.buffer)].data;
    const std::size_t stride = view.byteStride ? view.byteStride : element_size;
    const std::size_t needed = a.count == 0 ? 0 : a.byteOffset + stride * (a.count - 1) + element_size;
    if (view.byteOffset + view.byteLength > data.size() || needed > view.byteLength) {
      return error(name + " reaches beyond its buffer (" + std::to_string(view.byteOffset + needed) + " bytes of " +
                   std::to_string(data.size()) + ")");
    }
    std::vector<const unsigned char*> out(a.count);
    for (std::size_t i = 0; i < a.count; ++i) out[i] = data.data() + view.byteOffset + a.byteOffset + i * stride;
    return out;
  }

  // `components` floats per element: FLOAT, or integers (KHR_mesh_quantization), normalized or not.
  Result<std::vector<float>> floats(int index, int components) const {
    if (index < 0 || std::size_t(index) >= model.accessors.size()) {
      return error("accessor " + std::to_string(index) + " does not exist");
    }
    const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
    if (tinygltf::GetNumComponentsInType(std::uint32_t(a.type)) != components) {
      return error("accessor " + std::to_string(index) + " has " +
                   std::to_string(tinygltf::GetNumComponentsInType(std::uint32_t(a.type))) + " components, expected " +
                   std::to_string(components));
    }
    const int size = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType));
    if (size <= 0) return error("accessor " + std::to_string(index) + " has an unknown component type");
    auto bytes = elements(index, std::size_t(size * components));
    if (!bytes) return bytes.error();
    std::vector<float> out(a.count * std::size_t(components));
    for (std::size_t i = 0; i < a.count; ++i) {
      for (int c = 0; c < components; ++c) {
        const unsigned char* p = (*bytes)[i] + c * size;
        out[i * std::size_t(components) + std::size_t(c)] = component(p, a.componentType, a.normalized);
      }
    }
    return out;
  }

  static float component(const unsigned char* p, int type, bool normalized) {
    const auto as = [p]<class T>(T) {
      T v;
      std::memcpy(&v, p, sizeof v);
      return v;
    };
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: return as(float{});
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const float v = float(as(std::int8_t{}));
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        const float v = float(as(std::uint8_t{}));
        return normalized ? v / 255.0f : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        const float v = float(as(std::int16_t{}));
        return normalized ? std::max(v / 32767.0f, -1.0f) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        const float v = float(as(std::uint16_t{}));
        return normalized ? v / 65535.0f : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return float(as(std::uint32_t{}));
      default: return 0.0f;
    }
  }

  Result<std::vector<std::uint32_t>> indices(int index, std::size_t vertex_count) const {
    if (index < 0 || std::size_t(index) >= model.accessors.size()) {
      return error("accessor " + std::to_string(index) + " does not exist");
    }
    const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
    const int type = a.componentType;
    if (a.type != TINYGLTF_TYPE_SCALAR || (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                           type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                           type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
      return error("index accessor " + std::to_string(index) + " is not unsigned byte, short or int scalars");
    }
    auto bytes = elements(index, std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(type))));
    if (!bytes) return bytes.error();
    std::vector<std::uint32_t> out(a.count);
    for (std::size_t i = 0; i < a.count; ++i) {
      const auto v = std::uint32_t(component((*bytes)[i], type, false));
      if (v >= vertex_count) {
        return error("index accessor " + std::to_string(index) + ": index " + std::to_string(v) + " at " +
                     std::to_string(i) + " is beyond the " + std::to_string(vertex_count) + " vertices");
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
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    for (std::size_t i = 0; i + 2 < n; i += 3) t.push_back({v[i], v[i + 1], v[i + 2]});
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (std::size_t i = 0; i + 2 < n; ++i) {
      t.push_back(i % 2 == 0 ? std::array{v[i], v[i + 1], v[i + 2]} : std::array{v[i], v[i + 2], v[i + 1]});
    }
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (std::size_t i = 1; i + 1 < n; ++i) t.push_back({v[i], v[i + 1], v[0]});
  }
  return t;
}

glm::dmat4 local_matrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glm
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3) {
    m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
  }
  if (node.rotation.size() == 4) {
    m *= glm::mat4_cast(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

}  // namespace

float Scene::radius() const { return 0.5f * glm::length(bounds_max - bounds_min); }

Result<Scene> load_scene(const fs::path& path) {
  return guarded(path.string(), [&]() -> Result<Scene> {
    const std::string file = path.string();
    tinygltf::Model model;
    if (Status loaded = gltf::load_model(path, model); !loaded) return loaded.error();

    Scene scene;
    const Reader read{model, file};
    int scene_index = model.defaultScene;
    if (scene_index < 0) {
      if (model.scenes.empty()) return Error{file, "no scene to bake"};
      scene_index = 0;
      scene.notes.push_back("no default scene: using scene 0");
    }
    if (std::size_t(scene_index) >= model.scenes.size()) return Error{file, "the default scene does not exist"};

    std::vector<bool> on_path(model.nodes.size(), false);
    std::size_t ignored_primitives = 0;
    std::function<Status(int, const glm::dmat4&)> visit = [&](int n, const glm::dmat4& parent) -> Status {
      if (n < 0 || std::size_t(n) >= model.nodes.size()) return Error{file, "node " + std::to_string(n) + " does not exist"};
      if (on_path[std::size_t(n)]) return Error{file, "node " + std::to_string(n) + " is its own ancestor"};
      on_path[std::size_t(n)] = true;
      const tinygltf::Node& node = model.nodes[std::size_t(n)];
      const glm::dmat4 world = parent * local_matrix(node);
      if (node.mesh >= 0) {
        if (std::size_t(node.mesh) >= model.meshes.size()) {
          return Error{file, "node " + std::to_string(n) + " refers to mesh " + std::to_string(node.mesh) + ", which does not exist"};
        }
        const tinygltf::Mesh& mesh = model.meshes[std::size_t(node.mesh)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
          const tinygltf::Primitive& prim = mesh.primitives[p];
          const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
          if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            ++ignored_primitives;
            continue;
          }
          const auto position = prim.attributes.find("POSITION");
          if (position == prim.attributes.end()) return Error{file, "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p) + " has no POSITION"};
          auto positions = read.floats(position->second, 3);
          if (!positions) return positions.error();
          const std::size_t vertices = positions->size() / 3;
          if (const auto bad = std::find_if(positions->begin(), positions->end(), [](float x) { return !std::isfinite(x); });
              bad != positions->end()) {
            return Error{file, "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p) + ": POSITION of vertex " +
                                   std::to_string((bad - positions->begin()) / 3) + " is not finite"};
          }
          std::vector<std::uint32_t> order;
          if (prim.indices >= 0) {
            auto idx = read.indices(prim.indices, vertices);
            if (!idx) return idx.error();
            order = std::move(idx.value());
          } else {
            order.resize(vertices);
            std::iota(order.begin(), order.end(), 0u);
          }
          Instance inst;
          inst.node = n;
          inst.mesh = node.mesh;
          inst.primitive = int(p);
          inst.world = world;
          inst.triangles = triangles_of(order, mode);
          const bool mirrored = glm::determinant(glm::dmat3(world)) < 0;
          if (mirrored) {
            for (auto& t : inst.triangles) std::swap(t[1], t[2]);
          }
          inst.positions.resize(vertices);
          for (std::size_t v = 0; v < vertices; ++v) {
            const glm::dvec4 w = world * glm::dvec4((*positions)[3 * v], (*positions)[3 * v + 1], (*positions)[3 * v + 2], 1.0);
            inst.positions[v] = Vec3(w);
          }
          if (const auto normal = prim.attributes.find("NORMAL"); normal != prim.attributes.end()) {
            auto normals = read.floats(normal->second, 3);
            if (!normals) return normals.error();
            if (normals->size() != positions->size()) {
              return Error{file, "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p) + ": NORMAL and POSITION counts differ"};
            }
            const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(world));
            inst.normals.resize(vertices);
            for (std::size_t v = 0; v < vertices; ++v) {
              const glm::dvec3 nv = normal_matrix * glm::dvec3((*normals)[3 * v], (*normals)[3 * v + 1], (*normals)[3 * v + 2]);
              const double length = glm::length(nv);
              inst.normals[v] = length > 0 ? Vec3(nv / length) : Vec3(0);
            }
          }
          if (const auto color = prim.attributes.find("COLOR_0"); color != prim.attributes.end()) {
            const int components = color->second >= 0 && std::size_t(color->second) < model.accessors.size()
                                       ? tinygltf::GetNumComponentsInType(std::uint32_t(model.accessors[std::size_t(color->second)].type))
                                       : 4;
            auto colors = read.floats(color->second, components == 3 ? 3 : 4);
            if (!colors) return colors.error();
            if (colors->size() / std::size_t(components) != vertices) {
              return Error{file, "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p) + ": COLOR_0 and POSITION counts differ"};
            }
            inst.colors_have_alpha = components == 4;
            inst.colors.resize(vertices);
            for (std::size_t v = 0; v < vertices; ++v) {
              const float* c = colors->data() + v * std::size_t(components);
              inst.colors[v] = glm::vec4(c[0], c[1], c[2], components == 4 ? c[3] : 1.0f);
            }
          }
          scene.instances.push_back(std::move(inst));
        }
      }
      for (int child : node.children) {
        if (Status s = visit(child, world); !s) return s;
      }
      on_path[std::size_t(n)] = false;
      return success();
    };
    for (int root : model.scenes[std::size_t(scene_index)].nodes) {
      if (Status s = visit(root, glm::dmat4(1.0)); !s) return s.error();
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
    if (triangles == 0) return Error{file, "no triangles in the default scene"};
    return scene;
  });
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
