#pragma once
// The generated terrain of the AO benchmarks: 10 × 10 tiles of 24 × 24 quads (62,500 vertices,
// 115,200 triangles), a bumpy height field 10 units across. With `texcoords`, TEXCOORD_0 lays the
// tiles out as a 10 × 10 atlas over [0, 1]² (shared tile edges are equal floats).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <vector>

#include "matbake/scene.hpp"

namespace matbake::bench {

inline scene::Scene terrain(bool texcoords = false) {
  constexpr int kTiles = 10, kGrid = 24;
  scene::Scene s;
  for (int ty = 0; ty < kTiles; ++ty) {
    for (int tx = 0; tx < kTiles; ++tx) {
      scene::Instance tile;
      if (texcoords) tile.texcoords.emplace_back();
      for (int j = 0; j <= kGrid; ++j) {
        for (int i = 0; i <= kGrid; ++i) {
          const float x = float(tx) + float(i) / kGrid, y = float(ty) + float(j) / kGrid;
          const float z = 0.15f * std::sin(7 * x) * std::cos(5 * y) + 0.05f * std::sin(23 * x + 11 * y);
          tile.positions.push_back({x, y, z});
          if (texcoords) tile.texcoords[0].push_back({x / kTiles, y / kTiles});
        }
      }
      for (int j = 0; j < kGrid; ++j) {
        for (int i = 0; i < kGrid; ++i) {
          const auto at = [](int a, int b) { return std::uint32_t(b * (kGrid + 1) + a); };
          tile.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
          tile.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
      }
      s.instances.push_back(std::move(tile));
    }
  }
  s.bounds_min = {0, 0, -0.2f};
  s.bounds_max = {float(kTiles), float(kTiles), 0.2f};
  return s;
}

inline double seconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The median time of f over at least 3 runs and at least a second in all (at most 25 runs): a bake
// of a tenth of a second is otherwise at the mercy of one scheduler hiccup.
inline double median_seconds(const std::function<void()>& f) {
  std::vector<double> times;
  double total = 0;
  while (times.size() < 25 && (times.size() < 3 || total < 1.0)) {
    times.push_back(seconds_of(f));
    total += times.back();
  }
  std::nth_element(times.begin(), times.begin() + std::ptrdiff_t(times.size() / 2), times.end());
  return times[times.size() / 2];
}

}  // namespace matbake::bench
