#include "mikktspace.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <numbers>
#include <tuple>
#include <unordered_map>

namespace matbake::bake {
namespace {

// The reference's tests: a float is zero when not above the smallest normal float, a vector when
// each component is.
bool not_zero(float x) { return std::fabs(x) > FLT_MIN; }
bool not_zero(glm::vec3 v) { return not_zero(v.x) || not_zero(v.y) || not_zero(v.z); }
glm::vec3 normalized(glm::vec3 v) { return not_zero(v) ? v * (1.0f / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z)) : v; }
glm::vec3 projected(glm::vec3 v, glm::vec3 n) { return normalized(v - glm::dot(n, v) * n); }

// The threshold's cosine as the reference computes it for 180°: -1 in float.
const float kThresholdCos = float(std::cos(double(180.0f * float(std::numbers::pi) / 180.0f)));

struct Triangle {
  std::array<int, 3> vertex{};                // welded: the first corner with its position, normal and UV
  std::array<int, 3> neighbour{-1, -1, -1};   // across edge i (corner i to corner i + 1)
  std::array<int, 3> group{-1, -1, -1};       // the group of corner i
  glm::vec3 os{0.0f}, ot{0.0f};               // directions of increasing u and v, unit (or zero)
  bool orient = false;                        // its UVs keep its winding
  bool any = true;                            // UVs without area or a zero direction: joins any group
  int input = 0;                              // its place among the given triangles
};

struct Group {
  int vertex = -1;
  bool orient = false;
  std::vector<int> triangles;  // good triangles' indices
};

struct Tspace {
  glm::vec3 os{1.0f, 0.0f, 0.0f};
  bool orient = false;
};

// Corners with equal position, normal and UV (compared as floats: -0 equals 0) are one vertex, named
// by the first such corner.
std::vector<int> welded(const TriangleCorners& c) {
  struct Key {
    std::array<float, 8> v;
    bool operator==(const Key& o) const { return v == o.v; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      std::size_t h = 1469598103934665603ull;
      for (const float f : k.v) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &f, sizeof bits);
        h = (h ^ bits) * 1099511628211ull;
      }
      return h;
    }
  };
  std::unordered_map<Key, int, Hash> first;
  std::vector<int> vertex(c.positions.size());
  for (std::size_t i = 0; i < vertex.size(); ++i) {
    const glm::vec3 p = c.positions[i], n = c.normals[i];
    const glm::vec2 t = c.texcoords[i];
    Key key{{p.x + 0.0f, p.y + 0.0f, p.z + 0.0f, n.x + 0.0f, n.y + 0.0f, n.z + 0.0f, t.x + 0.0f, t.y + 0.0f}};
    vertex[i] = first.try_emplace(key, int(i)).first->second;
  }
  return vertex;
}

// A good triangle's UV derivatives and orientation.
void init_derivatives(Triangle& t, const TriangleCorners& c) {
  const glm::vec3 v1 = c.positions[std::size_t(t.vertex[0])], v2 = c.positions[std::size_t(t.vertex[1])],
                  v3 = c.positions[std::size_t(t.vertex[2])];
  const glm::vec2 t1 = c.texcoords[std::size_t(t.vertex[0])], t2 = c.texcoords[std::size_t(t.vertex[1])],
                  t3 = c.texcoords[std::size_t(t.vertex[2])];
  const float t21x = t2.x - t1.x, t21y = t2.y - t1.y, t31x = t3.x - t1.x, t31y = t3.y - t1.y;
  const glm::vec3 d1 = v2 - v1, d2 = v3 - v1;
  const float signed_area = t21x * t31y - t21y * t31x;
  const glm::vec3 os = t31y * d1 - t21y * d2, ot = -t31x * d1 + t21x * d2;
  t.orient = signed_area > 0;
  if (!not_zero(signed_area)) return;
  const float area = std::fabs(signed_area), length_s = glm::length(os), length_t = glm::length(ot);
  const float sign = t.orient ? 1.0f : -1.0f;
  if (not_zero(length_s)) t.os = (sign / length_s) * os;
  if (not_zero(length_t)) t.ot = (sign / length_t) * ot;
  t.any = !(not_zero(length_s / area) && not_zero(length_t / area));
}

// Neighbours across shared edges (by welded vertices, in opposite directions). An edge of more than
// two triangles pairs them in triangle order, each with the first unpaired one after it.
void find_neighbours(std::vector<Triangle>& tris) {
  struct Edge {
    int lo, hi, triangle, number;
  };
  std::vector<Edge> edges;
  for (int f = 0; f < int(tris.size()); ++f) {
    for (int e = 0; e < 3; ++e) {
      const int a = tris[std::size_t(f)].vertex[std::size_t(e)], b = tris[std::size_t(f)].vertex[std::size_t((e + 1) % 3)];
      edges.push_back({std::min(a, b), std::max(a, b), f, e});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return std::tie(x.lo, x.hi, x.triangle) < std::tie(y.lo, y.hi, y.triangle); });
  const auto from = [&](const Edge& e) { return tris[std::size_t(e.triangle)].vertex[std::size_t(e.number)]; };
  for (std::size_t i = 0; i < edges.size(); ++i) {
    Triangle& a = tris[std::size_t(edges[i].triangle)];
    if (a.neighbour[std::size_t(edges[i].number)] >= 0) continue;
    for (std::size_t j = i + 1; j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi; ++j) {
      Triangle& b = tris[std::size_t(edges[j].triangle)];
      if (from(edges[j]) == from(edges[i]) || b.neighbour[std::size_t(edges[j].number)] >= 0) continue;  // same direction, or paired
      a.neighbour[std::size_t(edges[i].number)] = edges[j].triangle;
      b.neighbour[std::size_t(edges[j].number)] = edges[i].triangle;
      break;
    }
  }
}

int corner_of(const Triangle& t, int vertex) {
  for (int i = 0; i < 3; ++i) {
    if (t.vertex[std::size_t(i)] == vertex) return i;
  }
  return -1;
}

// The group started at a corner grows across the edges beside its vertex, depth first (the edge
// after the corner, then the one before), to the triangles that share its orientation; a triangle
// that can join any takes the orientation of the first group to reach it.
void grow(std::vector<Triangle>& tris, std::vector<Group>& groups, int g, int start) {
  std::vector<int> stack{start};
  while (!stack.empty()) {
    const int f = stack.back();
    stack.pop_back();
    Triangle& t = tris[std::size_t(f)];
    Group& group = groups[std::size_t(g)];
    const int i = corner_of(t, group.vertex);
    if (i < 0 || t.group[std::size_t(i)] >= 0) continue;
    if (t.any && t.group == std::array<int, 3>{-1, -1, -1}) t.orient = group.orient;
    if (t.orient != group.orient) continue;
    group.triangles.push_back(f);
    t.group[std::size_t(i)] = g;
    for (const int next : {t.neighbour[std::size_t((i + 2) % 3)], t.neighbour[std::size_t(i)]}) {
      if (next >= 0) stack.push_back(next);  // the edge after the corner is taken first
    }
  }
}

std::vector<Group> make_groups(std::vector<Triangle>& tris) {
  std::vector<Group> groups;
  for (int f = 0; f < int(tris.size()); ++f) {
    for (int i = 0; i < 3; ++i) {
      Triangle& t = tris[std::size_t(f)];
      if (t.any || t.group[std::size_t(i)] >= 0) continue;
      const int g = int(groups.size());
      groups.push_back({t.vertex[std::size_t(i)], t.orient, {f}});
      t.group[std::size_t(i)] = g;
      for (const int next : {t.neighbour[std::size_t(i)], t.neighbour[std::size_t((i + 2) % 3)]}) {
        if (next >= 0) grow(tris, groups, g, next);
      }
    }
  }
  return groups;
}

// A vertex's tangent from the triangles of a subgroup: their u directions projected onto its normal,
// weighted by their corner angles there (also projected).
glm::vec3 tangent_of(const std::vector<int>& members, const std::vector<Triangle>& tris, int vertex, const TriangleCorners& c) {
  glm::vec3 sum(0.0f);
  const glm::vec3 n = c.normals[std::size_t(vertex)];
  for (const int f : members) {
    const Triangle& t = tris[std::size_t(f)];
    if (t.any) continue;
    const int i = corner_of(t, vertex);
    const glm::vec3 p1 = c.positions[std::size_t(vertex)];
    const glm::vec3 p0 = c.positions[std::size_t(t.vertex[std::size_t((i + 2) % 3)])], p2 = c.positions[std::size_t(t.vertex[std::size_t((i + 1) % 3)])];
    const float cosine = std::clamp(glm::dot(projected(p0 - p1, n), projected(p2 - p1, n)), -1.0f, 1.0f);
    sum += float(std::acos(double(cosine))) * projected(t.os, n);  // acos in double, as the reference
  }
  return normalized(sum);
}

// Each corner of a group's triangles gets the tangent of the triangles within the threshold of its
// own (with 180°, all but an exactly opposite one; those that can join any always).
void group_tangents(const Group& g, const std::vector<Triangle>& tris, const TriangleCorners& c, std::vector<Tspace>& out) {
  const glm::vec3 n = c.normals[std::size_t(g.vertex)];
  std::vector<std::pair<std::vector<int>, glm::vec3>> subgroups;
  for (const int f : g.triangles) {
    const Triangle& t = tris[std::size_t(f)];
    const glm::vec3 os = projected(t.os, n), ot = projected(t.ot, n);
    std::vector<int> members;
    for (const int other : g.triangles) {
      const Triangle& u = tris[std::size_t(other)];
      if (t.any || u.any || other == f ||
          (glm::dot(os, projected(u.os, n)) > kThresholdCos && glm::dot(ot, projected(u.ot, n)) > kThresholdCos)) {
        members.push_back(other);
      }
    }
    std::sort(members.begin(), members.end());
    auto found = std::find_if(subgroups.begin(), subgroups.end(), [&](const auto& s) { return s.first == members; });
    if (found == subgroups.end()) {
      const glm::vec3 tangent = tangent_of(members, tris, g.vertex, c);
      found = subgroups.insert(subgroups.end(), {std::move(members), tangent});
    }
    const int i = corner_of(t, g.vertex);
    out[std::size_t(3 * t.input + i)] = {found->second, g.orient};
  }
}

}  // namespace

std::vector<glm::vec4> mikktspace_tangents(const TriangleCorners& c) {
  const std::vector<int> vertex = welded(c);
  const int triangle_count = int(c.positions.size() / 3);
  std::vector<Triangle> good;
  std::vector<int> degenerate;
  for (int f = 0; f < triangle_count; ++f) {
    Triangle t;
    t.input = f;
    for (int i = 0; i < 3; ++i) t.vertex[std::size_t(i)] = vertex[std::size_t(3 * f + i)];
    const glm::vec3 p0 = c.positions[std::size_t(t.vertex[0])], p1 = c.positions[std::size_t(t.vertex[1])],
                    p2 = c.positions[std::size_t(t.vertex[2])];
    if (p0 == p1 || p0 == p2 || p1 == p2) {
      degenerate.push_back(f);
      continue;
    }
    init_derivatives(t, c);
    good.push_back(t);
  }
  find_neighbours(good);
  const std::vector<Group> groups = make_groups(good);
  std::vector<Tspace> spaces(c.positions.size());
  for (const Group& g : groups) group_tangents(g, good, c, spaces);
  // A degenerate triangle's corner copies the first good corner of its vertex.
  std::unordered_map<int, std::size_t> first_good;
  for (const Triangle& t : good) {
    for (int i = 0; i < 3; ++i) first_good.try_emplace(t.vertex[std::size_t(i)], std::size_t(3 * t.input + i));
  }
  for (const int f : degenerate) {
    for (int i = 0; i < 3; ++i) {
      const auto found = first_good.find(vertex[std::size_t(3 * f + i)]);
      if (found != first_good.end()) spaces[std::size_t(3 * f + i)] = spaces[found->second];
    }
  }
  std::vector<glm::vec4> tangents;
  tangents.reserve(spaces.size());
  for (const Tspace& s : spaces) tangents.emplace_back(s.os, s.orient ? 1.0f : -1.0f);
  return tangents;
}

}  // namespace matbake::bake
