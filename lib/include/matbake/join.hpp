#pragma once
// The one way matbake joins words into a message or a list ("a, b, c"), and splits a list.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

namespace matbake {

// The parts with `separator` between them. Appended in place, not as "literal" + std::string
// temporaries: GCC 12 at -O3 misreads those (a false -Wstringop-overflow).
inline std::string join(const std::vector<std::string>& parts, std::string_view separator) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) out.append(separator);
    out.append(parts[i]);
  }
  return out;
}

// The parts of `text` between each `separator` ("a,,b" has three; "" has one, empty).
inline std::vector<std::string> split(std::string_view text, char separator) {
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const std::size_t end = std::min(text.find(separator, start), text.size());
    parts.emplace_back(text.substr(start, end - start));
    if (end == text.size()) return parts;
    start = end + 1;
  }
}

}  // namespace matbake
