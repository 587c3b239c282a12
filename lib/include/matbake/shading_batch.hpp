#pragma once
// Schüler's four specular variants over arrays, in float: the form a renderer or a texture pass
// evaluates them in. Inputs are the dot products of make_geometry (structure of arrays) and the
// material per sample; the loop is branch-free so the compiler vectorises it (4 lanes with the
// x86-64 baseline SSE2). Against the float64 functions of shading.hpp evaluated on the same (float)
// inputs, the relative error of values ≥ 1e-6 is below 1e-5 (Full: 1e-4, from 1 − √Ks near Ks = 1);
// smaller values are within 1e-10 absolute (tests/unit/test_shading_batch.cpp, bench_shading).
// One difference: where Optimized's n·l/(l·h)³ leaves the float range (l and v both within ~1e-13
// of the horizon on opposite sides), the result is the largest finite float instead of a huge double.
#include <span>

#include "matbake/shading.hpp"

namespace matbake::shading {

struct SchulerBatch {
  std::span<const float> n_dot_l, n_dot_v, n_dot_h, l_dot_h;
  std::span<const float> ks, gloss;
};

// out[i] = schuler_specular(variant, sample i) (Schüler's intensity per unit irradiance).
// Every span must have out.size() elements (std::invalid_argument otherwise).
void schuler_specular_batch(SchulerVariant variant, const SchulerBatch& in, std::span<float> out);

}  // namespace matbake::shading
