#include "bounded_json.hpp"

#include <algorithm>

namespace matbake {

std::size_t json_depth(std::string_view text) {
  std::size_t depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

std::string json_size_problem(std::uint64_t size, std::size_t size_limit) {
  if (size <= size_limit) return {};
  return "holds " + std::to_string(size) + " bytes of JSON, over the " + std::to_string(size_limit) + " matbake reads";
}

std::string json_limit_problem(std::string_view text, std::size_t size_limit) {
  if (std::string problem = json_size_problem(text.size(), size_limit); !problem.empty()) return problem;
  if (const std::size_t depth = json_depth(text); depth > kJsonDepthLimit) {
    return "nests arrays and objects " + std::to_string(depth) + " deep, past the " + std::to_string(kJsonDepthLimit) +
           " levels matbake reads";
  }
  return {};
}

}  // namespace matbake
