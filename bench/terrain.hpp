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

// The median time of each of `bakes`, run in turn round after round (at least 3 rounds and 3 seconds
// in all, at most 25): a bake of a tenth of a second is otherwise at the mercy of one scheduler
// hiccup, and a drift of the machine's speed falls on all of them alike.
inline std::vector<double> median_seconds(const std::vector<std::function<void()>>& bakes) {
  std::vector<std::vector<double>> times(bakes.size());
  double total = 0;
  for (std::size_t round = 0; round < 25 && (round < 3 || total < 3.0); ++round) {
    for (std::size_t b = 0; b < bakes.size(); ++b) {
      times[b].push_back(seconds_of(bakes[b]));
      total += times[b].back();
    }
  }
  std::vector<double> medians;
  for (std::vector<double>& t : times) {
    std::nth_element(t.begin(), t.begin() + std::ptrdiff_t(t.size() / 2), t.end());
    medians.push_back(t[t.size() / 2]);
  }
  return medians;
}

}  // namespace matbake::bench
