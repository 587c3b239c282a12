// Prints docs/shading.md's albedo tables: the directional albedo of every catalog model over
// view angle × gloss × F0 (ks), by numerical integration, with the integration error.
// Diffuse models are evaluated with kd = 1, specular ones with their ks; kd = 1 for Strauss.
#include <tbb/parallel_for.h>

#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "matbake/shading_catalog.hpp"

int main() {
  using namespace matbake::shading;
  const std::vector<double> views = {0, 30, 60, 80, 89}, glosses = {0, 0.25, 0.5, 0.75, 1},
                            f0s = {0.02, 0.04, 0.2, 0.5, 1.0};
  const auto all = models();
  struct Cell {
    double view, gloss, ks;
    AlbedoEstimate albedo;
  };
  std::vector<std::vector<Cell>> cells(all.size());
  tbb::parallel_for(std::size_t(0), all.size(), [&](std::size_t i) {
    for (double view : views)
      for (double gloss : glosses)
        for (double ks : f0s) {
          const auto a = directional_albedo(all[i], {1.0, ks, gloss}, view * std::numbers::pi / 180, 192);
          cells[i].push_back({view, gloss, ks, a});
        }
  });
  std::printf("| model | built to conserve energy | max albedo | where (view°, g, ks) | cells > 1 (of %zu) | integration error there |\n",
              cells[0].size());
  std::printf("|---|---|---|---|---|---|\n");
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Cell* worst = &cells[i][0];
    int above = 0;
    for (const Cell& c : cells[i]) {
      if (c.albedo.value > worst->albedo.value) worst = &c;
      above += c.albedo.value > 1.0 + 3 * c.albedo.error + 1e-3;
    }
    std::printf("| %s | %s | %.4f | %g, %g, %g | %d | %.1e |\n", std::string(all[i].name).c_str(),
                all[i].conserves_energy ? "yes" : "no", worst->albedo.value, worst->view, worst->gloss, worst->ks, above,
                worst->albedo.error);
  }
  std::printf("\nAlbedo at ks = 1 (white specular; kd = 1 for the diffuse models), rows: view angle, columns: g\n\n");
  for (std::size_t i = 0; i < all.size(); ++i) {
    std::printf("**%s**\n\n| view° | g=0 | 0.25 | 0.5 | 0.75 | 1 |\n|---|---|---|---|---|---|\n", std::string(all[i].name).c_str());
    for (double view : views) {
      std::printf("| %g |", view);
      for (const Cell& c : cells[i]) {
        if (c.view == view && c.ks == 1.0) std::printf(" %.3f |", c.albedo.value);
      }
      std::printf("\n");
    }
    std::printf("\n");
  }
}
