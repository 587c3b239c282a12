#include "frames.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/mat3x3.hpp>

#include "mikktspace.hpp"

namespace matbake::bake {
namespace {

bool mirrored(const scene::Instance& inst) { return glm::determinant(glm::dmat3(inst.world)) < 0; }

// MikkTSpace leaves a tangent zero where a vertex's directions cancel or lie along its normal;
// glTF's TANGENT is a unit vector: any one across the normal serves (nothing in the UVs prefers one).
glm::vec3 perpendicular(const glm::vec3& n) {
  const glm::vec3 across = glm::cross(n, std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0));
  return glm::length(across) > 0 ? glm::normalize(across) : glm::vec3(1, 0, 0);
}

}  // namespace

std::array<std::uint32_t, 3> file_triangle(const scene::Instance& inst, std::size_t t) {
  const auto& c = inst.triangles[t];
  return mirrored(inst) ? std::array{c[0], c[2], c[1]} : c;
}

std::size_t file_corner(const scene::Instance& inst, std::size_t k) { return mirrored(inst) && k != 0 ? 3 - k : k; }

std::vector<glm::vec3> corner_normals(const scene::Instance& inst) {
  const auto& positions = inst.object.positions;
  std::vector<glm::vec3> normals(3 * inst.triangles.size());
  for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
    const auto c = file_triangle(inst, t);
    const glm::vec3 face = glm::cross(positions[c[1]] - positions[c[0]], positions[c[2]] - positions[c[0]]);
    const float length = glm::length(face);
    for (std::size_t k = 0; k < 3; ++k) {
      const glm::vec3 n = inst.object.normals.empty() ? (length > 0 ? face / length : glm::vec3(0, 0, 1))
                                                      : inst.object.normals[c[k]];
      normals[3 * t + file_corner(inst, k)] = n;
    }
  }
  return normals;
}

Result<std::vector<glm::vec4>> corner_tangents(const scene::Instance& inst, int texcoord) {
  if (inst.object.positions.size() != inst.positions.size()) {
    return Error{"", "internal: a bake's low-poly was loaded without its object-space attributes"};
  }
  const std::size_t corners = 3 * inst.triangles.size();
  std::vector<glm::vec4> tangents(corners);
  if (!inst.object.tangents.empty()) {
    for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
      for (std::size_t k = 0; k < 3; ++k) tangents[3 * t + k] = inst.object.tangents[inst.triangles[t][k]];
    }
    return tangents;
  }
  if (texcoord < 0 || std::size_t(texcoord) >= inst.texcoords.size() || inst.texcoords[std::size_t(texcoord)].empty()) {
    return Error{"", "internal: a bake's low-poly has no TEXCOORD_" + std::to_string(texcoord)};
  }
  const auto& uv = inst.texcoords[std::size_t(texcoord)];
  const std::vector<glm::vec3> normals = corner_normals(inst);
  std::vector<glm::vec3> file_positions(corners), file_normals(corners);
  std::vector<glm::vec2> file_uvs(corners);
  for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
    const auto c = file_triangle(inst, t);
    for (std::size_t k = 0; k < 3; ++k) {
      file_positions[3 * t + k] = inst.object.positions[c[k]];
      file_normals[3 * t + k] = normals[3 * t + file_corner(inst, k)];
      file_uvs[3 * t + k] = uv[c[k]];
    }
  }
  const std::vector<glm::vec4> mikk = mikktspace_tangents({file_positions, file_normals, file_uvs});
  for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const glm::vec4& m = mikk[3 * t + k];
      const glm::vec3 xyz = glm::length(glm::vec3(m)) > 0 ? glm::vec3(m) : perpendicular(file_normals[3 * t + k]);
      tangents[3 * t + file_corner(inst, k)] = glm::vec4(xyz, -m.w);
    }
  }
  return tangents;
}

Result<std::vector<CornerFrame>> corner_frames(const scene::Instance& inst, int texcoord) {
  auto tangents = corner_tangents(inst, texcoord);
  if (!tangents) return tangents.error();
  const std::vector<glm::vec3> normals = corner_normals(inst);
  const glm::dmat3 model(inst.world);
  const glm::dmat3 normal_matrix = glm::inverseTranspose(model);
  const auto unit = [](glm::dvec3 v) {
    const double length = glm::length(v);
    return length > 0 ? glm::vec3(v / length) : glm::vec3(0);
  };
  std::vector<CornerFrame> frames(tangents->size());
  for (std::size_t c = 0; c < frames.size(); ++c) {
    const glm::vec4& t = (*tangents)[c];
    CornerFrame& f = frames[c];
    f.tangent = unit(model * glm::dvec3(t));
    f.normal = unit(normal_matrix * glm::dvec3(normals[c]));
    f.bitangent = unit(glm::dvec3(glm::cross(f.normal, f.tangent)) * double(t.w));
  }
  return frames;
}

}  // namespace matbake::bake
