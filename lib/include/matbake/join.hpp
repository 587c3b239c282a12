#pragma once
// The one way matbake joins words into a message or a list: "a, b, c".
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

}  // namespace matbake
