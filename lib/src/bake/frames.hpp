#pragma once
// The low-poly's tangent basis per triangle corner, as a runtime's vertex shader hands it to the
// pixel shader (three.js with vertex tangents): world-space unit tangent, bitangent and normal.
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <vector>

#include "matbake/result.hpp"
#include "matbake/scene.hpp"

namespace matbake::bake {

// Triangle t's vertices in the file's winding: the scene reverses a mirrored node's triangles (to
// keep their facing in world space), and the file's order is what its normals, and so MikkTSpace's
// orientation test, agree with. The file's corner k of triangle t is the instance's file_corner(k).
std::array<std::uint32_t, 3> file_triangle(const scene::Instance& inst, std::size_t t);
std::size_t file_corner(const scene::Instance& inst, std::size_t k);

// glTF's TANGENT per corner (3 a triangle, in the instance's triangle order), object space: the
// file's where it has them, else MikkTSpace's over the file's positions, normals (flat where it has
// none, as glTF asks a runtime to make them) and UV set `texcoord`, with w negated — glTF's
// bitangent w · cross(N, T) points up the texture, against increasing v, where MikkTSpace's follows v.
// Where MikkTSpace gives no direction (zero), a unit vector across the normal: TANGENT is unit.
// Errors: the instance was loaded without its object-space attributes or that UV set.
Result<std::vector<glm::vec4>> corner_tangents(const scene::Instance& inst, int texcoord);

// The object-space normal per corner: the file's, else the face's (glTF's flat normals).
std::vector<glm::vec3> corner_normals(const scene::Instance& inst);

struct CornerFrame {
  glm::vec3 tangent, bitangent, normal;
};

// T = normalize(M · t), N = normalize(M⁻ᵀ · n), B = normalize(w · cross(N, T)), M the node's world
// matrix. Errors as corner_tangents'.
Result<std::vector<CornerFrame>> corner_frames(const scene::Instance& inst, int texcoord);

}  // namespace matbake::bake
