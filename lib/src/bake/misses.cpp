// Why a bake's rays missed, from what the two meshes and the probes tell: what its error and
// warnings name as the likely cause.
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "matbake/bake.hpp"

namespace matbake::bake {

Boxes compare_boxes(const scene::Scene& low, const scene::Scene& high) {
  Boxes out;
  const glm::dvec3 a0(low.bounds_min), a1(low.bounds_max), b0(high.bounds_min), b1(high.bounds_max);
  out.low_diagonal = glm::length(a1 - a0), out.high_diagonal = glm::length(b1 - b0);
  for (int k = 0; k < 3; ++k) {
    const double extent = a1[k] - a0[k];
    const double shared = std::max(0.0, std::min(a1[k], b1[k]) - std::max(a0[k], b0[k]));
    if (extent >= 0.1 * out.low_diagonal) {
      out.overlap = std::min(out.overlap, shared / extent);
      continue;
    }
    // Along an axis the low-poly hardly spans (a flat one's normal), the boxes overlap when their
    // gap is within the low-poly's size: farther is placement, nearer the cage's business.
    const double gap = std::max({0.0, b0[k] - a1[k], a0[k] - b1[k]});
    if (gap > out.low_diagonal) out.overlap = 0;
  }
  return out;
}

namespace {

// The reach (of the low-poly's diagonal) past which a miss is put down to holes, not the cage.
constexpr double kHoleReach = 0.25;

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

// A distance to suggest, rounded up to three significant digits: rounded down, the cage it names
// falls just short of the surfaces it was measured to reach.
std::string number_up(double v) {
  if (!(v > 0) || !std::isfinite(v)) return number(v);
  const double step = std::pow(10.0, std::floor(std::log10(v)) - 2);
  return number(std::ceil(v / step - 1e-6) * step);  // a float a hair above 0.2 is still 0.2
}

}  // namespace

std::string miss_cause(const Boxes& boxes, const TextureBake& texture, const Options& options, double diagonal, bool cage_mesh) {
  if (boxes.low_diagonal > 0 && boxes.high_diagonal > 0) {
    const double ratio = boxes.high_diagonal / boxes.low_diagonal;
    if (ratio >= 5 || ratio <= 0.2) {
      const int power = int(std::lround(std::log10(ratio)));
      const char* example = std::abs(power) == 2 ? ": centimetres against metres?" : std::abs(power) == 3 ? ": millimetres against metres?"
                            : std::abs(power) == 1                                ? ": millimetres against centimetres?"
                                                                                  : "";
      return "the high-poly's bounding box is " + number(ratio) + "× the low-poly's: the two are likely in different units (a "
             "factor of " + number(std::pow(10.0, power)) + example + ")";
    }
  }
  if (boxes.overlap < 0.5) {
    return "the two meshes' bounding boxes barely overlap (" + number(100 * boxes.overlap) +
           "% of the low-poly's extent along one axis): one is misplaced, or it is the wrong file";
  }
  if (2 * texture.faced_away > texture.misses) {
    return "most missed rays met only the backs of high-poly faces: its winding (or the low-poly's side of it) is flipped "
           "there";
  }
  // A cage reaching a quarter of the model's size would meet the far side of the model: the surface
  // those rays want is across a hole (an open base, a missing part), not beyond a small cage.
  if (const double farthest = std::max(texture.reach_front, texture.reach_back);
      boxes.low_diagonal > 0 && farthest > kHoleReach * boxes.low_diagonal) {
    return "the high-poly surface along the missed rays lies " + number(farthest / boxes.low_diagonal) +
           " of the low-poly's diagonal away, farther than any cage reaches: holes in the high-poly (the rays see "
           "its far side), parts of the low-poly it does not have, or high-poly parts standing that far off the "
           "low-poly (give them low-poly parts, or their own cage with match by_name)";
  }
  if (texture.reach_front > 0 || texture.reach_back > 0) {
    const double unit = options.absolute_distances || !(diagonal > 0) ? 1.0 : diagonal;
    std::string wider;
    if (texture.reach_front > 0 && cage_mesh) {
      wider = "the cage mesh " + number_up(texture.reach_front) + " (scene units) farther out";
      if (texture.reach_back > 0) wider += " and back " + number_up(texture.reach_back / unit) + (unit == 1 ? " (scene units)" : " (of the diagonal)");
      return "the cage is too small: " + wider + " would reach 95% of the missed rays that have the high-poly along them";
    }
    if (texture.reach_front > 0) wider = "front " + number_up(texture.reach_front / unit);
    if (texture.reach_back > 0) wider += std::string(wider.empty() ? "" : " and ") + "back " + number_up(texture.reach_back / unit);
    return "the cage is too small: " + wider + (options.absolute_distances ? " (scene units)" : " (of the diagonal)") +
           " would reach 95% of the missed rays that have the high-poly along them";
  }
  return "no high-poly surface lies along the missed rays within the low-poly's size: holes in the high-poly, or parts "
         "of the low-poly it does not have";
}

}  // namespace matbake::bake
