// Fits the gloss → roughness mapping: for g = i/32, the glTF roughness whose GGX lobe is nearest
// in least squares to Schüler's CookTorranceSimplified lobe (F0 = 0.04 on both), and prints
// both mappings' lobe errors as a Markdown table. With a path argument, also writes the table
// that lib/src/workflow/fitted_roughness.inc holds.
//   build/bench/fit_gloss_roughness [lib/src/workflow/fitted_roughness.inc]
#include <tbb/parallel_for.h>

#include <cstdio>
#include <fstream>
#include <vector>

#include "matbake/workflow.hpp"

using namespace matbake::workflow;

int main(int argc, char** argv) {
  const LobeQuadrature q = make_lobe_quadrature(48);
  constexpr int kCount = 33;
  std::vector<double> best(kCount), walter_error(kCount), best_error(kCount);
  tbb::parallel_for(0, kCount, [&](int i) {
    const double g = i / 32.0;
    best[i] = best_roughness(q, kDielectricF0, g);
    walter_error[i] = lobe_error(q, kDielectricF0, g, kDielectricF0, roughness_from_gloss(g, RoughnessMapping::walter));
    best_error[i] = lobe_error(q, kDielectricF0, g, kDielectricF0, best[i]);
  });
  std::printf("| g | roughness, Walter | lobe error | roughness, fitted | lobe error |\n|---|---|---|---|---|\n");
  for (int i = 0; i < kCount; i += 2) {
    std::printf("| %.4f | %.4f | %.1f%% | %.4f | %.1f%% |\n", i / 32.0,
                roughness_from_gloss(i / 32.0, RoughnessMapping::walter), 100 * walter_error[i], best[i],
                100 * best_error[i]);
  }
  if (argc > 1) {
    std::ofstream out(argv[1]);
    for (double r : best) out << "    " << std::fixed << r << ",\n";
    if (!out) {
      std::fprintf(stderr, "fit_gloss_roughness: %s: cannot write\n", argv[1]);
      return 1;
    }
  }
  return 0;
}
