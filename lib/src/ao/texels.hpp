#pragma once
// The texels a texture bake traces: which surface point each texel centre maps to (coverage with a
// tie rule, nearest points for touched texels), and the padding around them afterwards.
#include <glm/vec2.hpp>

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "matbake/ao.hpp"

namespace matbake::ao::texels {

// A surface point a texel samples: triangle `triangle` of instance `instance`, at (x, y) in texel
// space (texel (i, j) has its centre at (i, j); unwrapped, so it may lie outside [0, W) × [0, H)).
struct SurfacePoint {
  std::uint32_t texel;  // j × width + i, wrapped
  std::uint32_t instance;
  std::uint32_t triangle;
  float x, y;
};

struct Coverage {
  std::vector<SurfacePoint> points;  // sorted by texel; within a texel, in scene order
  std::size_t covered = 0, touched = 0, overlapped = 0;
  std::size_t triangles = 0, degenerate_uv = 0, wrapped = 0, too_large = 0, instances_without_uv = 0;
};
constexpr int kMaxCopies = 64;  // of the texture a triangle's UVs may span (wrapping)

// Every texel's points at once, for the whole texture: a bake that traces as it goes takes them
// tile by tile instead (tile, cover_tile). The result is the same for any number of threads.
// Errors: a layout mapping more than max_points surface points (hundreds of stacked copies).
constexpr std::size_t kMaxSurfacePoints = std::size_t{1} << 27;  // 2.7 GB of points
Result<Coverage> cover(const scene::Scene& scene, const TextureTarget& target, int width, int height,
                       std::size_t max_points = kMaxSurfacePoints);
std::string too_many_points(std::size_t max_points, int width, int height);  // that error's message

// Unwrapped cells [i0, i1] × [j0, j1] (whole numbers, inclusive).
struct CellRect {
  double i0, i1, j0, j1;
};
// A triangle's cells that wrap into one tile (a triangle over several tiles, or over copies of the
// texture, has a fragment in each).
struct Fragment {
  std::uint32_t instance, triangle;
  CellRect cells;
};
// The texture in kTile × kTile tiles (the last row and column cut), each with the fragments of the
// triangles that may cover or touch its texels, in scene order: a tile's coverage needs only its
// own, so tiles are covered (and traced) one at a time, in parallel.
constexpr int kTile = 32;
struct Tiling {
  int width = 0, height = 0, columns = 0, rows = 0;  // texels; tiles
  std::vector<std::vector<Fragment>> fragments;      // per tile, row × columns + column
  std::size_t triangles = 0, degenerate_uv = 0, wrapped = 0, too_large = 0, instances_without_uv = 0;
};
Tiling tile(const scene::Scene& scene, const TextureTarget& target, int width, int height);

// One tile's points (as Coverage's: sorted by texel, within a texel in scene order) and counts;
// the rest is scratch, reused from tile to tile.
struct TilePoints {
  std::vector<SurfacePoint> points;
  std::size_t covered = 0, touched = 0, overlapped = 0;
  struct Touch {
    double distance;
    SurfacePoint point;
  };
  std::vector<SurfacePoint> found;
  std::vector<std::uint32_t> count;
  std::vector<Touch> nearest;
};
void cover_tile(const scene::Scene& scene, const TextureTarget& target, const Tiling& tiling, std::size_t tile,
                TilePoints& out);

// Every tile with fragments covered, in parallel, and visit(tile, its points) called on the thread
// that covered it. Errors: the tiles together map more than max_points surface points (too_many_points).
Status cover_tiles(const scene::Scene& scene, const TextureTarget& target, const Tiling& tiling, std::size_t max_points,
                   const std::function<void(std::size_t tile, const TilePoints& points)>& visit);

// A triangle's UVs in texel space.
struct UvTriangle {
  glm::dvec2 a, b, c;
};
// (Texel space of target.tile_origin's tile: its corner at −½, −½.)
inline UvTriangle uv_triangle(const scene::Instance& inst, const TextureTarget& target, std::size_t triangle, int width, int height) {
  const auto& uv = inst.texcoords[std::size_t(target.texcoord)];
  const auto& t = inst.triangles[triangle];
  const glm::dvec2 origin(target.tile_origin);
  const auto texel = [&](std::uint32_t v) {
    return glm::dvec2((double(uv[v].x) - origin.x) * width - 0.5, (double(uv[v].y) - origin.y) * height - 0.5);
  };
  return {texel(t[0]), texel(t[1]), texel(t[2])};
}

// A texel's size on a triangle's surface: √(world area / texel area), from twice the triangle's
// world area and its UVs in texel space (the scale of a ray origin's offset).
inline float texel_size(double world_area2, const UvTriangle& uv) {
  const double uv_area2 = std::abs((uv.b.x - uv.a.x) * (uv.c.y - uv.a.y) - (uv.b.y - uv.a.y) * (uv.c.x - uv.a.x));
  return float(std::sqrt(world_area2 / uv_area2));
}

// Barycentric weights (of a, b, c) of the point of the triangle nearest to p (p's own when inside).
glm::dvec3 nearest_weights(const UvTriangle& t, const glm::dvec2& p);

// Texels within `padding` of a mapped one take the value of the nearest mapped texel (Euclidean,
// ties averaged); returns how many were padded. Texels farther away are left as they are.
// `values` holds `channels` interleaved floats per texel (the distances are found once for all).
std::size_t pad_channels(std::vector<float>& values, int channels, const std::vector<bool>& mapped, int width,
                         int height, int padding);
inline std::size_t pad(std::vector<float>& values, const std::vector<bool>& mapped, int width, int height, int padding) {
  return pad_channels(values, 1, mapped, width, height, padding);
}

// Per texel (j × width + i) the index of one mapped texel nearest to it (Euclidean; of ties, the one
// the transform meets first), −1 when none is mapped. Linear in the texels, however far.
std::vector<std::int64_t> nearest_mapped(const std::vector<bool>& mapped, int width, int height);

// Of each texel in `wanted` (indices j × width + i), one mapped texel nearest to it (Euclidean), −1
// when none is mapped. A few wanted texels near mapped ones are each searched ring by ring around
// it; else the transform over the whole texture answers (nearest_mapped), which costs more than a
// few hundred searches.
std::vector<std::int64_t> nearest_mapped_to(const std::vector<bool>& mapped, int width, int height,
                                            const std::vector<std::size_t>& wanted);

}  // namespace matbake::ao::texels
