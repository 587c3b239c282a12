#include "matbake/near_names.hpp"

#include <algorithm>
#include <utility>

namespace matbake {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::vector<std::string> near_names(std::string_view name, const std::vector<std::string>& known) {
  std::vector<std::pair<std::size_t, std::string>> scored;
  for (const std::string& k : known) {
    const std::size_t d = edit_distance(name, k);
    const bool prefix = !name.empty() && (k.starts_with(name) || name.starts_with(k));
    if (d <= std::max<std::size_t>(2, name.size() / 3) || prefix) scored.emplace_back(prefix ? 0 : d, k);
  }
  std::stable_sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::string> names;
  for (auto& [d, n] : scored) names.push_back(std::move(n));
  return names;
}

std::string did_you_mean(std::string_view name, const std::vector<std::string>& known) {
  const std::vector<std::string> near = near_names(name, known);
  if (near.empty()) return "";
  std::string text = "; did you mean " + near[0];
  if (near.size() > 1) text += " or " + near[1];
  return text + "?";
}

}  // namespace matbake
