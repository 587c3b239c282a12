// Fits the gloss → roughness mapping: for g = i/32 and each F0 of kFittedF0, the glTF roughness
// whose GGX lobe (Schlick F0) is nearest in least squares to Schüler's CookTorranceSimplified
// lobe (Ks = F0). Prints, for a few F0, the lobe error of the Walter mapping, of the Khronos
// converter's roughness = 1 − g, and of the fit, as Markdown. With a path argument, also writes
// the table that lib/src/workflow/fitted_roughness.inc holds.
//   build/bench/fit_gloss_roughness [lib/src/workflow/fitted_roughness.inc]
#include <tbb/parallel_for.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <vector>

#include "matbake/workflow.hpp"

using namespace matbake::workflow;

int main(int argc, char** argv) {
  const LobeQuadrature q = make_lobe_quadrature(48);
  constexpr std::size_t kGlosses = 33, kRows = std::size(kFittedF0);
  std::vector<double> best(kGlosses * kRows);
  tbb::parallel_for(std::size_t(0), best.size(), [&](std::size_t k) {
    best[k] = best_roughness(q, kFittedF0[k / kGlosses], double(k % kGlosses) / 32.0);
  });
  std::printf("| F0 | g | lobe error: Walter | 1 − g (Khronos) | fitted | roughness: Walter | fitted |\n"
              "|---|---|---|---|---|---|---|\n");
  for (std::size_t row : {std::size_t(1), std::size_t(3), std::size_t(5)}) {
    const double f0 = kFittedF0[row];
    for (std::size_t i = 0; i < kGlosses; i += 8) {
      const double g = double(i) / 32.0, fitted = best[row * kGlosses + i];
      const double walter = roughness_from_gloss(g, RoughnessMapping::walter);
      std::printf("| %.2f | %.2f | %.1f%% | %.1f%% | %.1f%% | %.3f | %.3f |\n", f0, g,
                  100 * lobe_error(q, f0, g, f0, walter), 100 * lobe_error(q, f0, g, f0, 1 - g),
                  100 * lobe_error(q, f0, g, f0, fitted), walter, fitted);
    }
  }
  if (argc > 1) {
    std::ofstream out(argv[1]);
    for (std::size_t row = 0; row < kRows; ++row) {
      out << "    {{  // F0 " << kFittedF0[row] << "\n";
      for (std::size_t i = 0; i < kGlosses; ++i) out << "        " << std::fixed << best[row * kGlosses + i] << ",\n";
      out << "    }},\n";
    }
    if (!out) {
      std::fprintf(stderr, "fit_gloss_roughness: %s: cannot write\n", argv[1]);
      return 1;
    }
  }
  return 0;
}
