// Spec-gloss → metal-rough on representative materials, ours against the Khronos converter, as
// Markdown (README "Workflow conversion"). Kd is our choice per material; Ks (F0) is Schüler's
// Table 2.5.1 (metals' colours from the article's 8-bit values via gamma 2.2).
#include <cmath>
#include <cstdio>

#include "matbake/workflow_maps.hpp"

using namespace matbake;
using workflow::Vec3;

struct Row {
  const char* name;
  Vec3 kd, ks;
};

int main() {
  const auto decode = [](double r, double g, double b) {
    return Vec3(std::pow(r / 255, 2.2), std::pow(g / 255, 2.2), std::pow(b / 255, 2.2));
  };
  const Row rows[] = {
      {"water (Kd 0.05)", Vec3(0.05), Vec3(0.02)},
      {"red plastic", Vec3(0.5, 0.05, 0.05), Vec3(0.05)},
      {"painted wall (F0 0.04)", Vec3(0.6, 0.55, 0.5), Vec3(0.04)},
      {"diamond", Vec3(0.02), Vec3(0.17)},
      {"copper", Vec3(0), decode(250, 208, 192)},
      {"gold", Vec3(0), decode(255, 229, 158)},
      {"silver", Vec3(0), decode(252, 250, 245)},
      {"dusty gold (Kd 0.1)", Vec3(0.1), decode(255, 229, 158)},
      {"tinted varnish (coloured Ks, Kd)", Vec3(0.3, 0.2, 0.1), Vec3(0.2, 0.15, 0.1)},
  };
  std::printf("| material | g | metallic: ours / Khronos | ΔE*ab: ours / Khronos | max abs ΔF0: ours / Khronos | lobe error: ours / Khronos |\n"
              "|---|---|---|---|---|---|\n");
  for (const Row& row : rows) {
    for (double g : {0.25, 0.75}) {
      const std::vector<pack::SourceInput> in = {
          {"kd", {}, {row.kd.r, row.kd.g, row.kd.b}}, {"ks", {}, {row.ks.r, row.ks.g, row.ks.b}}, {"gloss", {}, {g}}};
      workflow::ConversionReport report;
      auto out = workflow::metal_rough_from_spec_gloss(*pack::load_sources(in, {}), workflow::RoughnessMapping::fitted,
                                                       report);
      const double khronos_m = workflow::khronos_base_metallic(row.kd, row.ks).metallic;
      const auto& e = report.errors;
      const auto& k = report.khronos_errors;
      std::printf("| %s | %.2f | %.3f / %.3f | %.2f / %.2f | %.4f / %.4f | %.1f%% / %.1f%% |\n", row.name, g,
                  out->find("metallic")->pixels[0], khronos_m, e.diffuse_delta_e.max, k.diffuse_delta_e.max,
                  e.specular.max, k.specular.max, 100 * e.lobe.max, 100 * k.lobe.max);
    }
  }
  return 0;
}
