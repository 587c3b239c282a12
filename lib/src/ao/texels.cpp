#include "texels.hpp"

#include <glm/geometric.hpp>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

namespace matbake::ao::texels {
namespace {

using glm::dvec2;

double cross(const dvec2& a, const dvec2& b) { return a.x * b.y - a.y * b.x; }

// The edge function of a → b at p, evaluated from the lexicographically smaller endpoint so that
// the two triangles sharing an edge get exactly opposite values (the tie rule needs exact zeros).
double edge(const dvec2& a, const dvec2& b, const dvec2& p) {
  const bool forward = a.x < b.x || (a.x == b.x && a.y < b.y);
  const dvec2& lo = forward ? a : b;
  const dvec2& hi = forward ? b : a;
  const double e = cross(hi - lo, p - lo);
  return forward ? e : -e;
}

// A centre exactly on an edge belongs to the triangle that traverses the edge in a half-open half
// circle of directions: the neighbour across it traverses it the other way, so exactly one of them
// owns it (and, around a shared vertex, exactly one of the fan).
bool owns(const dvec2& a, const dvec2& b) {
  const dvec2 d = b - a;
  return d.y > 0 || (d.y == 0 && d.x < 0);
}

bool inside(const UvTriangle& t, const dvec2& p) {
  const double e[3] = {edge(t.a, t.b, p), edge(t.b, t.c, p), edge(t.c, t.a, p)};
  const bool own[3] = {owns(t.a, t.b), owns(t.b, t.c), owns(t.c, t.a)};
  for (int k = 0; k < 3; ++k) {
    if (e[k] < 0 || (e[k] == 0 && !own[k])) return false;
  }
  return true;
}


// Squared distance transform of one row or column (Felzenszwalb and Huttenlocher 2012): the lower
// envelope of the parabolas (q − r)² + f(r), in place. Unmapped samples hold kFar, a finite stand-in
// for infinity that keeps the envelope's intersections finite.
constexpr double kFar = 1e20;
// With `site`, site[q] is the r whose parabola is lowest at q.
void distance_1d(double* f, std::size_t n, std::size_t stride, std::vector<double>& d, std::vector<int>& v,
                 std::vector<double>& z, int* site = nullptr) {
  const auto at = [&](long q) { return f[std::size_t(q) * stride]; };
  std::size_t k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  const auto meet = [&](long q, long r) {  // where q's parabola passes below r's
    return ((at(q) + double(q) * double(q)) - (at(r) + double(r) * double(r))) / (2.0 * double(q - r));
  };
  for (long q = 1; q < long(n); ++q) {
    double s = meet(q, v[k]);
    while (s <= z[k]) s = meet(q, v[--k]);  // z[0] = −∞ stops it
    ++k;
    v[k] = int(q), z[k] = s, z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (long q = 0; q < long(n); ++q) {
    while (z[k + 1] < double(q)) ++k;
    const long r = v[k];
    d[std::size_t(q)] = double(q - r) * double(q - r) + at(r);
    if (site) site[std::size_t(q) * stride] = int(r);
  }
  for (std::size_t q = 0; q < n; ++q) f[q * stride] = d[q];
}

}  // namespace

// Ericson, Real-Time Collision Detection 5.1.5, in barycentric form.
glm::dvec3 nearest_weights(const UvTriangle& t, const dvec2& p) {
  const dvec2 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const dvec2 bp = p - t.b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const dvec2 cp = p - t.c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denominator = 1 / (va + vb + vc);
  const double v = vb * denominator, w = vc * denominator;
  return {1 - v - w, v, w};
}

namespace {

const double kReach = std::sqrt(0.5);  // half a texel diagonal: how far a touched texel's centre may be

// The cross-section of a positively oriented triangle with the line y: [lo, hi] (empty when
// lo > hi), from its edges' half-planes. on_edge: a horizontal edge lies on the line.
struct Span {
  double lo, hi;
  bool on_edge;
};
Span span_at(const UvTriangle& tri, double y) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Span span{-kInf, kInf, false};
  for (const auto& [a, b] : {std::pair{tri.a, tri.b}, std::pair{tri.b, tri.c}, std::pair{tri.c, tri.a}}) {
    const dvec2 d = b - a;
    if (d.y == 0) {  // inside where d.x (y − a.y) ≥ 0
      const double e = d.x * (y - a.y);
      if (e < 0) return {kInf, -kInf, false};
      span.on_edge |= e == 0;
      continue;
    }
    const double x = a.x + d.x * (y - a.y) / d.y;  // inside on the left of a → b
    if (d.y > 0) span.hi = std::min(span.hi, x);
    else span.lo = std::max(span.lo, x);
  }
  return span;
}

// Which cells of a triangle for_each_cell visits: those whose centre is inside (with the tie
// rule), or those outside it that may lie within reach of it (a superset).
enum class Cells { inside, near };
constexpr double kNarrow = 8;  // texels: narrower triangles are scanned over their bounding box

struct Box {
  double x0, x1, y0, y1;
};
Box bounds(const UvTriangle& t) {
  return {std::min({t.a.x, t.b.x, t.c.x}), std::max({t.a.x, t.b.x, t.c.x}), std::min({t.a.y, t.b.y, t.c.y}),
          std::max({t.a.y, t.b.y, t.c.y})};
}

// Calls visit(i, j) for the `cells` of triangle `tri` (positively oriented, texel space) within the
// unwrapped cells `rect`, row by row. A row's cells a texel or more inside its cross-section are
// inside however the crossings round: only the few near its ends are tested, so a triangle costs
// its perimeter, not its bounding box.
template <class Visit>
void for_each_cell(const UvTriangle& tri, const CellRect& rect, Cells cells, Visit&& visit) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Box box = bounds(tri);
  if (box.x1 - box.x0 < kNarrow) {  // a few cells a row: their tests cost less than the crossings
    const double margin = cells == Cells::inside ? 0.0 : kReach;
    const double j_last = std::min(box.y1 + margin, rect.j1), i_last = std::min(box.x1 + margin, rect.i1);
    for (double j = std::max(std::ceil(box.y0 - margin), rect.j0); j <= j_last; ++j) {
      for (double i = std::max(std::ceil(box.x0 - margin), rect.i0); i <= i_last; ++i) {
        if (cells == Cells::near || inside(tri, dvec2(i, j))) visit(i, j);
      }
    }
    return;
  }
  if (cells == Cells::inside) {
    const double j_last = std::min(box.y1, rect.j1);
    for (double j = std::max(std::ceil(box.y0), rect.j0); j <= j_last; ++j) {
      const Span row = span_at(tri, j);
      const double first = std::max({std::ceil(box.x0), std::ceil(row.lo - 1), rect.i0});
      const double last = std::min({box.x1, row.hi + 1, rect.i1});
      for (double i = first; i <= last; ++i) {
        const bool sure = !row.on_edge && i >= row.lo + 1 && i <= row.hi - 1;
        if (sure || inside(tri, dvec2(i, j))) visit(i, j);
      }
    }
    return;
  }
  const double j_last = std::min(std::floor(box.y1 + kReach), rect.j1);
  for (double j = std::max(std::ceil(box.y0 - kReach), rect.j0); j <= j_last; ++j) {
    // The cross-section of the band of rows within reach (at its two sides, and the vertices in
    // it), widened by the reach and half a texel against rounding; the row's sure inside (covered
    // by the first pass) skipped.
    const double band = kReach + 0.01;
    double lo = kInf, hi = -kInf;
    for (double y : {j - band, j + band}) {
      const Span side = span_at(tri, y);
      if (side.lo <= side.hi) lo = std::min(lo, side.lo), hi = std::max(hi, side.hi);
    }
    for (const dvec2& v : {tri.a, tri.b, tri.c}) {
      if (std::abs(v.y - j) <= band) lo = std::min(lo, v.x), hi = std::max(hi, v.x);
    }
    const Span row = span_at(tri, j);
    const double sure_first = row.on_edge ? kInf : std::ceil(row.lo + 1), sure_last = std::floor(row.hi - 1);
    const double first = std::max({std::ceil(box.x0 - kReach), rect.i0, std::ceil(lo - kReach - 0.5)});
    const double last = std::min({std::floor(box.x1 + kReach), rect.i1, hi + kReach + 0.5});
    for (double i = first; i <= last; ++i) {
      if (i >= sure_first && i <= sure_last) {
        i = sure_last;
        continue;
      }
      visit(i, j);
    }
  }
}

// The runs of unwrapped cells first..last of an axis (n texels, wrapped by `wrap`) each of whose
// cells wraps into the same tile, in order: a run ends at a tile's edge and where the wrapped
// index turns (a period's end, a mirror); clamped cells beyond the texture are one run.
struct AxisRun {
  double first, last;
  std::size_t tile;
};
void axis_runs(double first, double last, int n, Wrap wrap, std::vector<AxisRun>& runs) {
  runs.clear();
  const long long size = n, end = (long long)last;
  for (auto p = (long long)first; p <= end;) {
    const long long q = wrapped_index(p, size, wrap);
    long long run_end = end;
    if (wrap != Wrap::clamp_to_edge || (p >= 0 && p < size)) {
      const bool down = wrap == Wrap::mirrored_repeat && ((p % (2 * size)) + 2 * size) % (2 * size) >= size;
      const long long tile_first = q / kTile * kTile, tile_last = std::min(tile_first + kTile, size) - 1;
      run_end = std::min(run_end, p + (down ? q - tile_first : tile_last - q));
    } else if (p < 0) {
      run_end = std::min(run_end, -1LL);
    }
    runs.push_back({double(p), double(run_end), std::size_t(q / kTile)});
    p = run_end + 1;
  }
}

// Farther from the origin (in texels) a triangle's copies wrap by whole numbers no double holds.
constexpr double kFarthest = 1e15;

}  // namespace

Tiling tile(const scene::Scene& scene, const TextureTarget& target, int width, int height) {
  Tiling out;
  out.width = width, out.height = height;
  out.columns = (width + kTile - 1) / kTile, out.rows = (height + kTile - 1) / kTile;
  out.fragments.resize(std::size_t(out.columns) * std::size_t(out.rows));
  // A triangle's bounding box may cover the texture several times over (a tiled floor); beyond
  // kMaxCopies it would cost unbounded time for a texture no viewer could show.
  const double max_cells = double(kMaxCopies) * double(width) * double(height) + 1024;
  std::vector<AxisRun> columns, rows;
  for (std::size_t k : target.instances) {
    const scene::Instance& inst = scene.instances[k];
    if (std::size_t(target.texcoord) >= inst.texcoords.size() || inst.texcoords[std::size_t(target.texcoord)].empty()) {
      ++out.instances_without_uv;
      continue;
    }
    for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
      const UvTriangle uv = uv_triangle(inst, target, t, width, height);
      const Box box = bounds(uv);
      // The tile alone: a triangle wholly outside it (or not finite) is none of its business, not
      // even its edge texels' (the bake counts such triangles once, not per tile).
      if (target.tile_only && !(box.x0 < width - 0.5 && box.x1 > -0.5 && box.y0 < height - 0.5 && box.y1 > -0.5)) continue;
      const double area2 = cross(uv.b - uv.a, uv.c - uv.a);
      const double longest2 = std::max({glm::dot(uv.b - uv.a, uv.b - uv.a), glm::dot(uv.c - uv.a, uv.c - uv.a),
                                        glm::dot(uv.c - uv.b, uv.c - uv.b)});
      if (!std::isfinite(area2) || !(std::abs(area2) > 1e-12 * longest2)) {
        ++out.degenerate_uv;
        continue;
      }
      CellRect cells{std::ceil(box.x0 - kReach), std::floor(box.x1 + kReach), std::ceil(box.y0 - kReach),
                     std::floor(box.y1 + kReach)};
      if (target.tile_only) {
        cells = {std::max(cells.i0, 0.0), std::min(cells.i1, width - 1.0), std::max(cells.j0, 0.0), std::min(cells.j1, height - 1.0)};
      }
      if ((cells.i1 - cells.i0 + 1) * (cells.j1 - cells.j0 + 1) > max_cells ||
          std::max({std::abs(box.x0), std::abs(box.x1), std::abs(box.y0), std::abs(box.y1)}) > kFarthest) {
        ++out.too_large;
        continue;
      }
      ++out.triangles;
      if (box.x0 < -0.5 || box.y0 < -0.5 || box.x1 > width - 0.5 || box.y1 > height - 0.5) ++out.wrapped;
      axis_runs(cells.i0, cells.i1, width, target.wrap_s, columns);
      axis_runs(cells.j0, cells.j1, height, target.wrap_t, rows);
      for (const AxisRun& row : rows) {
        for (const AxisRun& column : columns) {
          out.fragments[row.tile * std::size_t(out.columns) + column.tile].push_back(
              {std::uint32_t(k), std::uint32_t(t), {column.first, column.last, row.first, row.last}});
        }
      }
    }
  }
  return out;
}

void cover_tile(const scene::Scene& scene, const TextureTarget& target, const Tiling& tiling, std::size_t tile,
                TilePoints& out) {
  const long long x0 = (long long)(tile % std::size_t(tiling.columns)) * kTile;
  const long long y0 = (long long)(tile / std::size_t(tiling.columns)) * kTile;
  const auto texel_of = [&](double i, double j, std::size_t& local) {
    const long long x = wrapped_index((long long)i, tiling.width, target.wrap_s);
    const long long y = wrapped_index((long long)j, tiling.height, target.wrap_t);
    local = std::size_t((y - y0) * kTile + (x - x0));
    return std::uint32_t(y * tiling.width + x);
  };
  const auto oriented = [&](const Fragment& f) {
    const UvTriangle uv = uv_triangle(scene.instances[f.instance], target, f.triangle, tiling.width, tiling.height);
    return cross(uv.b - uv.a, uv.c - uv.a) > 0 ? uv : UvTriangle{uv.a, uv.c, uv.b};
  };
  out.found.clear();
  out.count.assign(std::size_t(kTile) * kTile, 0);
  out.covered = out.touched = out.overlapped = 0;
  const std::vector<Fragment>& fragments = tiling.fragments[tile];
  // Centres inside a triangle (the tie rule takes each shared edge's once).
  for (const Fragment& f : fragments) {
    for_each_cell(oriented(f), f.cells, Cells::inside, [&](double i, double j) {
      std::size_t local;
      out.found.push_back({texel_of(i, j, local), f.instance, f.triangle, float(i), float(j)});
      ++out.count[local];
    });
  }
  for (std::uint32_t c : out.count) out.covered += c > 0, out.overlapped += c > 1;
  // Texels no centre covers, within reach of a triangle: its nearest point (the nearest triangle's;
  // on a tie, the first in scene order).
  constexpr double kNone = std::numeric_limits<double>::infinity();
  out.nearest.assign(out.count.size(), {kNone, {}});
  for (const Fragment& f : fragments) {
    const UvTriangle tri = oriented(f);
    for_each_cell(tri, f.cells, Cells::near, [&](double i, double j) {
      std::size_t local;
      const std::uint32_t texel = texel_of(i, j, local);
      if (out.count[local]) return;
      const dvec2 centre(i, j);
      const glm::dvec3 w = nearest_weights(tri, centre);
      const dvec2 q = w.x * tri.a + w.y * tri.b + w.z * tri.c;
      const double distance = glm::length(q - centre);
      if (distance <= kReach && distance < out.nearest[local].distance) {
        out.nearest[local] = {distance, {texel, f.instance, f.triangle, float(q.x), float(q.y)}};
      }
    });
  }
  for (std::size_t local = 0; local < out.count.size(); ++local) {
    if (out.nearest[local].distance == kNone) continue;
    out.count[local] = 1;
    ++out.touched;
  }
  // Counting sort by texel (within the tile, texel order is local order): stable, so scene order
  // within a texel.
  std::uint32_t offset = 0;
  for (std::uint32_t& c : out.count) {
    const std::uint32_t n = c;
    c = offset;
    offset += n;
  }
  out.points.resize(offset);
  for (const SurfacePoint& p : out.found) {
    const auto local = std::size_t((long long)(p.texel / std::uint32_t(tiling.width)) - y0) * kTile +
                       std::size_t((long long)(p.texel % std::uint32_t(tiling.width)) - x0);
    out.points[out.count[local]++] = p;
  }
  for (std::size_t local = 0; local < out.count.size(); ++local) {
    if (out.nearest[local].distance != kNone) out.points[out.count[local]++] = out.nearest[local].point;
  }
}

std::string too_many_points(std::size_t max_points, int width, int height) {
  return "its UV layout maps more than " + std::to_string(max_points) + " surface points into the " + std::to_string(width) +
         "x" + std::to_string(height) +
         " texture (placements or UV copies stacked on the same texels): give each placement its own texture, or bake a "
         "smaller one";
}

Status cover_tiles(const scene::Scene& scene, const TextureTarget& target, const Tiling& tiling, std::size_t max_points,
                   const std::function<void(std::size_t tile, const TilePoints& points)>& visit) {
  std::atomic<std::size_t> total{0};
  tbb::enumerable_thread_specific<TilePoints> scratch;
  tbb::parallel_for(std::size_t{0}, tiling.fragments.size(), [&](std::size_t t) {
    if (tiling.fragments[t].empty() || total.load(std::memory_order_relaxed) > max_points) return;
    TilePoints& found = scratch.local();
    cover_tile(scene, target, tiling, t, found);
    total += found.points.size();
    visit(t, found);
  });
  if (total > max_points) return Error{"", too_many_points(max_points, tiling.width, tiling.height)};
  return success();
}

Result<Coverage> cover(const scene::Scene& scene, const TextureTarget& target, int width, int height,
                       std::size_t max_points) {
  const Tiling tiling = tile(scene, target, width, height);
  Coverage out;
  out.triangles = tiling.triangles, out.degenerate_uv = tiling.degenerate_uv, out.wrapped = tiling.wrapped;
  out.too_large = tiling.too_large, out.instances_without_uv = tiling.instances_without_uv;
  std::vector<std::vector<SurfacePoint>> tile_points(tiling.fragments.size());
  std::vector<std::array<std::size_t, 3>> tile_counts(tiling.fragments.size());
  const Status covered = cover_tiles(scene, target, tiling, max_points, [&](std::size_t t, const TilePoints& found) {
    tile_points[t] = found.points;
    tile_counts[t] = {found.covered, found.touched, found.overlapped};
  });
  if (!covered) return covered.error();
  std::size_t total = 0;
  for (const auto& points : tile_points) total += points.size();
  std::vector<std::uint32_t> first(std::size_t(width) * std::size_t(height) + 1, 0);
  for (std::size_t t = 0; t < tile_points.size(); ++t) {
    for (const SurfacePoint& p : tile_points[t]) ++first[p.texel + 1];
    out.covered += tile_counts[t][0], out.touched += tile_counts[t][1], out.overlapped += tile_counts[t][2];
  }
  for (std::size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
  out.points.resize(total);
  for (const std::vector<SurfacePoint>& points : tile_points) {
    for (const SurfacePoint& p : points) out.points[first[p.texel]++] = p;
  }
  return out;
}

namespace {

// The squared distance transform of the mapped texels, columns then rows, each line on its own (in
// parallel, each range with its own scratch). With `sites`, per pass the line position of the
// nearest site: a texel's nearest mapped texel is column c = sites.rows[t] of its row, and there
// the row sites.columns[row × w + c].
struct Sites {
  std::vector<int> columns, rows;
};
std::vector<double> squared_distances(const std::vector<bool>& mapped, std::size_t w, std::size_t h, Sites* sites) {
  std::vector<double> d2(w * h);
  for (std::size_t i = 0; i < w * h; ++i) d2[i] = mapped[i] ? 0.0 : kFar;
  const auto lines = [&](std::size_t count, std::size_t length, std::size_t start_step, std::size_t stride,
                         std::vector<int>* site) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 16), [&](const tbb::blocked_range<std::size_t>& range) {
      std::vector<double> scratch(length);
      std::vector<int> v(length);
      std::vector<double> z(length + 1);
      for (std::size_t line = range.begin(); line != range.end(); ++line) {
        distance_1d(&d2[line * start_step], length, stride, scratch, v, z, site ? &(*site)[line * start_step] : nullptr);
      }
    });
  };
  if (sites) sites->columns.resize(w * h), sites->rows.resize(w * h);
  lines(w, h, 1, w, sites ? &sites->columns : nullptr);
  lines(h, w, w, 1, sites ? &sites->rows : nullptr);
  return d2;
}

}  // namespace

std::vector<std::int64_t> nearest_mapped(const std::vector<bool>& mapped, int width, int height) {
  const std::size_t w = std::size_t(width), h = std::size_t(height);
  Sites sites;
  const std::vector<double> d2 = squared_distances(mapped, w, h, &sites);
  std::vector<std::int64_t> nearest(w * h, -1);
  for (std::size_t y = 0; y < h; ++y) {
    for (std::size_t x = 0; x < w; ++x) {
      const std::size_t t = y * w + x;
      if (d2[t] >= kFar) continue;  // nothing is mapped
      const auto column = std::size_t(sites.rows[t]);
      nearest[t] = std::int64_t(std::size_t(sites.columns[y * w + column]) * w + column);
    }
  }
  return nearest;
}

namespace {

// The nearest mapped texel to (x, y), −1 when none is found before `budget` (texels looked at,
// counted down) runs out. Ring r (the square at that Chebyshev distance) lies at least r away, so
// the search stops at the first ring beyond the best distance found.
std::int64_t nearest_by_rings(const std::vector<bool>& mapped, long w, long h, long x, long y, std::int64_t& budget) {
  std::int64_t best = -1;
  long best_d2 = std::numeric_limits<long>::max();
  const auto consider = [&](long xx, long yy) {
    if (xx < 0 || yy < 0 || xx >= w || yy >= h || !mapped[std::size_t(yy * w + xx)]) return;
    const long d2 = (xx - x) * (xx - x) + (yy - y) * (yy - y);
    if (d2 < best_d2) best_d2 = d2, best = yy * w + xx;
  };
  consider(x, y);
  for (long r = 1; r * r <= best_d2 && r <= std::max(w, h); ++r) {
    if ((budget -= 8 * r) < 0) return -1;
    for (long d = -r; d <= r; ++d) {
      consider(x + d, y - r), consider(x + d, y + r);
      if (d > -r && d < r) consider(x - r, y + d), consider(x + r, y + d);
    }
  }
  return best;
}

}  // namespace

std::vector<std::int64_t> nearest_mapped_to(const std::vector<bool>& mapped, int width, int height,
                                            const std::vector<std::size_t>& wanted) {
  // The searches may look at as many texels as the texture holds (the transform's passes look at
  // each several times): beyond that, the transform.
  auto budget = std::int64_t(width) * std::int64_t(height);
  std::vector<std::int64_t> out(wanted.size(), -1);
  bool searched = true;
  for (std::size_t i = 0; searched && i < wanted.size(); ++i) {
    out[i] = nearest_by_rings(mapped, width, height, long(wanted[i] % std::size_t(width)), long(wanted[i] / std::size_t(width)), budget);
    searched = out[i] >= 0;
  }
  if (searched) return out;
  const std::vector<std::int64_t> all = nearest_mapped(mapped, width, height);
  for (std::size_t i = 0; i < wanted.size(); ++i) out[i] = all[wanted[i]];
  return out;
}

std::size_t pad_channels(std::vector<float>& values, int channels, const std::vector<bool>& mapped, int width,
                         int height, int padding) {
  if (padding <= 0) return 0;
  const std::size_t w = std::size_t(width), h = std::size_t(height), c = std::size_t(channels);
  const std::vector<double> d2 = squared_distances(mapped, w, h, nullptr);
  const double limit = double(padding) * padding;
  const std::vector<float> source = values;
  std::atomic<std::size_t> padded{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, h, 16), [&](const tbb::blocked_range<std::size_t>& rows) {
    std::size_t padded_here = 0;
    std::vector<double> sum(c);
    for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
      for (std::size_t x = 0; x < w; ++x) {
        const double d = d2[y * w + x];
        if (d == 0 || d > limit) continue;
        // Every mapped texel at exactly this squared distance: for each column offset, at most the two
        // rows with dx² + dy² = d.
        const auto r = long(std::floor(std::sqrt(d)));
        std::fill(sum.begin(), sum.end(), 0.0);
        int count = 0;
        for (long dx = -r; dx <= r; ++dx) {
          const double rest = d - double(dx) * double(dx);
          const auto dy = long(std::llround(std::sqrt(std::max(0.0, rest))));
          if (double(dy) * double(dy) != rest) continue;
          for (long sy : {-dy, dy}) {
            const long xx = long(x) + dx, yy = long(y) + sy;
            if (xx >= 0 && yy >= 0 && xx < long(w) && yy < long(h) && mapped[std::size_t(yy) * w + std::size_t(xx)]) {
              const std::size_t from = (std::size_t(yy) * w + std::size_t(xx)) * c;
              for (std::size_t k = 0; k < c; ++k) sum[k] += source[from + k];
              ++count;
            }
            if (dy == 0) break;
          }
        }
        if (count) {
          for (std::size_t k = 0; k < c; ++k) values[(y * w + x) * c + k] = float(sum[k] / count);
          ++padded_here;
        }
      }
    }
    padded += padded_here;
  });
  return padded;
}

}  // namespace matbake::ao::texels
