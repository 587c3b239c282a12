#pragma once
// MikkTSpace tangents (Mikkelsen 2011): the basis glTF asks a runtime to compute where a primitive
// has no TANGENT, and the one Blender, Substance and xNormal bake tangent-space normal maps in. The
// default angular threshold (180°), triangles given corner by corner, float arithmetic as the
// reference does, so that its decisions (a triangle's UV orientation, which corners are one vertex,
// which triangles are degenerate) come out the same and a normal map baked in this basis decodes in
// the one a runtime makes (checked against three.js's port in tests).
//
// The rules, in short: corners with equal position, normal and UV are one vertex. Per triangle, the
// direction of increasing u (and v) over its surface, and whether its UVs keep or mirror its winding.
// Per vertex, the triangles around it that reach each other across shared edges and agree on that
// orientation form a group; its tangent is their directions projected onto the vertex normal,
// weighted by each triangle's corner angle. A triangle whose UVs have no area joins the first group
// that reaches it; a degenerate one (two equal positions) copies the tangent of its vertex from a
// good triangle. What nothing gives stays (1, 0, 0) with sign -1.
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <span>
#include <vector>

namespace matbake::bake {

struct TriangleCorners {
  std::span<const glm::vec3> positions;  // three a triangle
  std::span<const glm::vec3> normals;    // unit length, one a corner
  std::span<const glm::vec2> texcoords;  // one a corner
};

// Each corner's tangent: xyz of unit length, w the bitangent's sign (bitangent = w · cross(normal,
// tangent), glTF's TANGENT). The spans must be of one length, a multiple of 3.
std::vector<glm::vec4> mikktspace_tangents(const TriangleCorners& corners);

}  // namespace matbake::bake
