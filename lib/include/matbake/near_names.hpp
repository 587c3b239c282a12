#pragma once
// "Did you mean": the known names closest to one that was not found (a manifest key, a flag, a
// layout, a material), for error messages.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace matbake {

// Levenshtein distance (insertions, deletions and substitutions of one byte each).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The names within a small edit distance of `name` (at most 2, or a third of its length), or that
// it starts or that start it, nearest first; ties keep the order of `known`.
std::vector<std::string> near_names(std::string_view name, const std::vector<std::string>& known);

// "; did you mean X?" (or "X or Y"), or "" when nothing is near: appended to an error message.
std::string did_you_mean(std::string_view name, const std::vector<std::string>& known);

}  // namespace matbake
