#pragma once
// A glTF scene flattened for ray casting: every triangle primitive reachable from the default
// scene's node graph, in world space. Only what the scene references is read: nodes outside it,
// images and animations are not loaded.
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/enum_names.hpp"
#include "matbake/result.hpp"

namespace matbake::scene {

using Vec3 = glm::vec3;

// One primitive placed by one node (a mesh instanced by two nodes gives two).
struct Instance {
  int node = -1, mesh = -1, primitive = -1;
  std::string name;                               // the placing node's, else its mesh's; may be empty
  int material = -1;                              // the primitive's material; -1: none
  glm::dmat4 world{1.0};                          // node to world
  std::vector<Vec3> positions;                    // world space, one per vertex of the primitive
  std::vector<Vec3> normals;                      // world space, unit; empty when the file has none
  std::vector<glm::vec4> colors;                  // COLOR_0 as floats, alpha 1 when the file's are RGB;
  bool colors_have_alpha = false;                 // empty when the file has none
  std::vector<std::array<std::uint32_t, 3>> triangles;  // strips and fans converted; facing kept
                                                         // under mirroring transforms
  // TEXCOORD_n as floats (n the index; an empty entry: the file has no set n). Read only when
  // SceneContent::texcoords asks: a per-vertex bake does not need them.
  std::vector<std::vector<glm::vec2>> texcoords;
  // The primitive's own POSITION, NORMAL and TANGENT as the file has them (object space; a runtime
  // computes tangents from these, then transforms them). Read only when SceneContent::object_space
  // asks; `tangents` is empty when the file has none.
  struct ObjectSpace {
    std::vector<Vec3> positions, normals;
    std::vector<glm::vec4> tangents;
  } object;
};

// What a load reads beyond positions, normals, colours and triangles.
struct SceneContent {
  bool texcoords = false;
  bool object_space = false;  // Instance::object: what a bake's tangent basis is computed from
};

struct Scene {
  std::vector<Instance> instances;
  std::vector<std::string> notes;  // what was skipped and why (points, lines, ...)
  Vec3 bounds_min{0}, bounds_max{0};
  float radius() const;            // half the bounding box diagonal
};

// Reads .gltf or .glb (Draco, meshopt, quantized and sparse geometry decoded). Errors name the file:
// malformed JSON or GLB, any index out of range (at its JSON pointer), accessors or buffer views
// beyond their buffers, compressed data its decoder refuses, indices beyond the vertex count, buffer or image URIs that
// leave the file's folder (absolute or with ..), a node reached twice (a cycle, or two parents:
// glTF nodes form strict trees), no default scene, no triangles. Node chains of any depth are
// walked without recursion.
Result<Scene> load_scene(const std::filesystem::path& path, const SceneContent& content = {});

// Vertex normals from faces (ch. 12): the sum over the faces around a vertex of the face normal
// weighted equally (12.31), by face area (12.32) or by the face's angle at the vertex (12.33).
// Degenerate faces (zero area) are skipped. A vertex in no valid face keeps its normal from the
// file when there is one, else takes the area-weighted normal of the whole primitive, else +z;
// fallbacks are counted.
enum class NormalWeighting { equal, area, angle };
inline constexpr NameTable<NormalWeighting, 3> kNormalWeightingNames{
    {{NormalWeighting::equal, "equal"}, {NormalWeighting::area, "area"}, {NormalWeighting::angle, "angle"}}};
struct NormalResult {
  std::vector<Vec3> normals;
  std::size_t fallbacks = 0;
  std::size_t degenerate_faces = 0;
};
NormalResult vertex_normals(const std::vector<Vec3>& positions,
                            const std::vector<std::array<std::uint32_t, 3>>& triangles, NormalWeighting weighting,
                            const std::vector<Vec3>& original = {});

}  // namespace matbake::scene
