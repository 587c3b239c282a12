#include "texels.hpp"

#include <glm/geometric.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
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

// A run of one instance's triangles: coverage is worked out per chunk in parallel and merged in
// chunk order, so the result (and the order of points within a texel) is the serial one for any
// number of threads. A chunk ends at kChunkTriangles or at kChunkCells texels of UV area, whichever
// comes first: a low-poly of a few hundred triangles over a 2048² texture is many chunks, not one.
constexpr std::size_t kChunkTriangles = 2048;
constexpr double kChunkCells = 65536;
struct Chunk {
  std::uint32_t instance;
  std::size_t first, last;
  double cells;  // the triangles' UV area in texels (those within max_cells): what to reserve
};

struct Touch {
  double distance;
  SurfacePoint point;
};

// What one chunk found: its centres (first pass), its touches (second), its triangles' tallies.
struct ChunkCoverage {
  std::vector<SurfacePoint> points;
  std::vector<Touch> touches;
  std::size_t triangles = 0, degenerate_uv = 0, wrapped = 0, too_large = 0;
};

// Stops every chunk once the chunks together hold more than `limit` points: each adds its count in
// batches, so the shared total never exceeds the true one and the decision is the serial one.
class PointBudget {
 public:
  explicit PointBudget(std::size_t limit) : limit_(limit) {}
  bool add(std::size_t n) { return (total_ += n) <= limit_; }
  bool exhausted() const { return total_.load(std::memory_order_relaxed) > limit_; }

 private:
  std::size_t limit_;
  std::atomic<std::size_t> total_{0};
};
constexpr std::size_t kBudgetBatch = 4096;

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
// rule), or those outside it that may lie within half a texel diagonal of it (a superset).
enum class Cells { inside, near };
constexpr double kNarrow = 8;  // texels: narrower triangles are scanned over their bounding box

struct Raster {
  const scene::Scene& scene;
  const TextureTarget& target;
  int width, height;
  double max_cells;  // of a triangle's bounding box (kMaxCopies textures)

  std::uint32_t texel_at(double i, double j) const {
    return std::uint32_t(wrapped_index((long long)j, height, target.wrap_t) * width + wrapped_index((long long)i, width, target.wrap_s));
  }

  // The chunk's usable triangles, positively oriented in texel space, and their `cells`, row by
  // row. A row's cells a texel or more inside its cross-section are inside however the crossings
  // round: only the few near its ends are tested, so a triangle costs its perimeter, not its
  // bounding box. `tally` counts the triangles (first pass only). visit returns false to stop.
  template <class Visit>
  bool for_each_cell(const Chunk& chunk, Cells cells, ChunkCoverage* tally, Visit&& visit) const {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double reach = std::sqrt(0.5);
    const scene::Instance& inst = scene.instances[chunk.instance];
    for (std::size_t t = chunk.first; t < chunk.last; ++t) {
      const UvTriangle uv = uv_triangle(inst, target.texcoord, t, width, height);
      const double area2 = cross(uv.b - uv.a, uv.c - uv.a);
      const double longest2 = std::max({glm::dot(uv.b - uv.a, uv.b - uv.a), glm::dot(uv.c - uv.a, uv.c - uv.a),
                                        glm::dot(uv.c - uv.b, uv.c - uv.b)});
      if (!std::isfinite(area2) || !(std::abs(area2) > 1e-12 * longest2)) {
        if (tally) ++tally->degenerate_uv;
        continue;
      }
      const UvTriangle tri = area2 > 0 ? uv : UvTriangle{uv.a, uv.c, uv.b};
      const double x0 = std::min({tri.a.x, tri.b.x, tri.c.x}), x1 = std::max({tri.a.x, tri.b.x, tri.c.x});
      const double y0 = std::min({tri.a.y, tri.b.y, tri.c.y}), y1 = std::max({tri.a.y, tri.b.y, tri.c.y});
      const double i0 = std::ceil(x0 - reach), i1 = std::floor(x1 + reach);
      const double j0 = std::ceil(y0 - reach), j1 = std::floor(y1 + reach);
      if ((i1 - i0 + 1) * (j1 - j0 + 1) > max_cells) {
        if (tally) ++tally->too_large;
        continue;
      }
      if (tally) {
        ++tally->triangles;
        if (x0 < -0.5 || y0 < -0.5 || x1 > width - 0.5 || y1 > height - 0.5) ++tally->wrapped;
      }
      if (x1 - x0 < kNarrow) {  // a few cells a row: their tests cost less than the crossings
        const double margin = cells == Cells::inside ? 0.0 : reach;
        for (double j = std::ceil(y0 - margin); j <= y1 + margin; ++j) {
          for (double i = std::ceil(x0 - margin); i <= x1 + margin; ++i) {
            if (cells == Cells::inside && !inside(tri, dvec2(i, j))) continue;
            if (!visit(t, tri, i, j)) return false;
          }
        }
        continue;
      }
      if (cells == Cells::inside) {
        for (double j = std::ceil(y0); j <= y1; ++j) {
          const Span row = span_at(tri, j);
          const double first = std::max(std::ceil(x0), std::ceil(row.lo - 1)), last = std::min(x1, row.hi + 1);
          for (double i = first; i <= last; ++i) {
            const bool sure = !row.on_edge && i >= row.lo + 1 && i <= row.hi - 1;
            if ((sure || inside(tri, dvec2(i, j))) && !visit(t, tri, i, j)) return false;
          }
        }
        continue;
      }
      for (double j = j0; j <= j1; ++j) {
        // The cross-section of the band of rows within reach (at its two sides, and the vertices
        // in it), widened by the reach and half a texel against rounding; the row's sure inside
        // (covered by the first pass) skipped.
        const double band = reach + 0.01;
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
        const double first = std::max(i0, std::ceil(lo - reach - 0.5)), last = std::min(i1, hi + reach + 0.5);
        for (double i = first; i <= last; ++i) {
          if (i >= sure_first && i <= sure_last) {
            i = sure_last;
            continue;
          }
          if (!visit(t, tri, i, j)) return false;
        }
      }
    }
    return true;
  }
};

}  // namespace

Result<Coverage> cover(const scene::Scene& scene, const TextureTarget& target, int width, int height,
                       std::size_t max_points) {
  Coverage out;
  const double reach = std::sqrt(0.5);  // half a texel diagonal
  // A triangle's bounding box may cover the texture several times over (a tiled floor); beyond
  // kMaxCopies it would cost unbounded time for a texture no viewer could show.
  const Raster raster{scene, target, width, height, double(kMaxCopies) * double(width) * double(height) + 1024};
  std::vector<Chunk> chunks;
  for (std::size_t k : target.instances) {
    const scene::Instance& inst = scene.instances[k];
    if (std::size_t(target.texcoord) >= inst.texcoords.size() || inst.texcoords[std::size_t(target.texcoord)].empty()) {
      ++out.instances_without_uv;
      continue;
    }
    std::size_t first = 0;
    double cells = 0;
    for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
      const UvTriangle uv = uv_triangle(inst, target.texcoord, t, width, height);
      const double area = std::abs(cross(uv.b - uv.a, uv.c - uv.a)) / 2;
      if (area <= raster.max_cells) cells += area;  // false for NaN
      if (t + 1 - first == kChunkTriangles || cells >= kChunkCells || t + 1 == inst.triangles.size()) {
        chunks.push_back({std::uint32_t(k), first, t + 1, cells});
        first = t + 1, cells = 0;
      }
    }
  }
  std::vector<ChunkCoverage> parts(chunks.size());
  PointBudget budget(max_points);
  const auto each_chunk = [&](auto&& work) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t c = range.begin(); c != range.end() && !budget.exhausted(); ++c) work(chunks[c], parts[c]);
    });
  };
  // Centres inside a triangle (the tie rule takes each shared edge's once).
  each_chunk([&](const Chunk& chunk, ChunkCoverage& part) {
    std::size_t unbudgeted = 0;
    part.points.reserve(std::size_t(std::min(chunk.cells, kChunkCells)) + 64);  // a chunk's centres ≈ its area
    raster.for_each_cell(chunk, Cells::inside, &part, [&](std::size_t t, const UvTriangle&, double i, double j) {
      part.points.push_back({raster.texel_at(i, j), chunk.instance, std::uint32_t(t), float(i), float(j)});
      if (++unbudgeted < kBudgetBatch) return true;
      unbudgeted = 0;
      return budget.add(kBudgetBatch);
    });
  });
  std::size_t centres = 0;
  for (const ChunkCoverage& part : parts) centres += part.points.size();
  const auto too_many = [&](const std::string& what) {
    return Error{"", "its UV layout " + what + " more than " + std::to_string(max_points) + " surface points into the " +
                         std::to_string(width) + "x" + std::to_string(height) +
                         " texture (placements or UV copies stacked on the same texels): give each placement its own "
                         "texture, or bake a smaller one"};
  };
  if (budget.exhausted() || centres > max_points) return too_many("maps");
  std::vector<std::uint32_t> count(std::size_t(width) * std::size_t(height), 0);
  for (const ChunkCoverage& part : parts) {
    for (const SurfacePoint& p : part.points) ++count[p.texel];
    out.triangles += part.triangles, out.degenerate_uv += part.degenerate_uv;
    out.wrapped += part.wrapped, out.too_large += part.too_large;
  }
  for (std::uint32_t c : count) {
    out.covered += c > 0;
    out.overlapped += c > 1;
  }
  // Texels no centre covers, within reach of a triangle: its nearest point (the nearest triangle's;
  // on a tie, the first in scene order).
  each_chunk([&](const Chunk& chunk, ChunkCoverage& part) {
    std::size_t unbudgeted = 0;
    raster.for_each_cell(chunk, Cells::near, nullptr, [&](std::size_t t, const UvTriangle& tri, double i, double j) {
      const std::uint32_t texel = raster.texel_at(i, j);
      if (count[texel]) return true;
      const dvec2 centre(i, j);
      const glm::dvec3 w = nearest_weights(tri, centre);
      const dvec2 q = w.x * tri.a + w.y * tri.b + w.z * tri.c;
      const double distance = glm::length(q - centre);
      if (distance > reach) return true;
      part.touches.push_back({distance, {texel, chunk.instance, std::uint32_t(t), float(q.x), float(q.y)}});
      if (++unbudgeted < kBudgetBatch) return true;
      unbudgeted = 0;
      return budget.add(kBudgetBatch);
    });
  });
  std::vector<Touch> touches;
  for (ChunkCoverage& part : parts) {
    touches.insert(touches.end(), part.touches.begin(), part.touches.end());
    std::vector<Touch>().swap(part.touches);
  }
  if (budget.exhausted() || centres + touches.size() > max_points) return too_many("maps and touches");
  std::stable_sort(touches.begin(), touches.end(), [](const Touch& a, const Touch& b) {
    return a.point.texel < b.point.texel || (a.point.texel == b.point.texel && a.distance < b.distance);
  });
  for (std::size_t first = 0; first < touches.size(); ++first) {
    if (first > 0 && touches[first].point.texel == touches[first - 1].point.texel) continue;
    ++count[touches[first].point.texel];
    ++out.touched;
  }
  // Counting sort by texel: stable (scene order within a texel; a touched texel has one point) and
  // linear in the points.
  std::uint32_t offset = 0;
  for (std::uint32_t& c : count) {
    const std::uint32_t n = c;
    c = offset;
    offset += n;
  }
  out.points.resize(offset);
  for (ChunkCoverage& part : parts) {
    for (const SurfacePoint& p : part.points) out.points[count[p.texel]++] = p;
    std::vector<SurfacePoint>().swap(part.points);  // the peak: all points once, and one chunk's
  }
  for (std::size_t first = 0; first < touches.size(); ++first) {
    if (first > 0 && touches[first].point.texel == touches[first - 1].point.texel) continue;
    out.points[count[touches[first].point.texel]++] = touches[first].point;
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
