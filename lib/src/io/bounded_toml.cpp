#include "bounded_toml.hpp"

#include <cctype>

namespace matbake {
namespace {

bool digit_at(std::string_view text, std::size_t at) {
  return at < text.size() && std::isdigit(static_cast<unsigned char>(text[at]));
}

// The index after the string that starts at `at` (a quote): basic or literal, one line or multi-line.
std::size_t after_string(std::string_view text, std::size_t at) {
  const char quote = text[at];
  const bool multi = text.compare(at, 3, std::string(3, quote)) == 0;
  const std::string_view end = multi ? std::string_view(quote == '"' ? "\"\"\"" : "'''") : std::string_view(&text[at], 1);
  for (std::size_t i = at + (multi ? 3 : 1); i < text.size(); ++i) {
    if (quote == '"' && text[i] == '\\') {
      ++i;  // an escape: the next character is the string's
    } else if (!multi && text[i] == '\n') {
      return i;  // unterminated: toml++ says so
    } else if (text.compare(i, end.size(), end) == 0) {
      return i + end.size();
    }
  }
  return text.size();
}

}  // namespace

TomlDepth toml_key_depth(std::string_view text) {
  TomlDepth deepest;
  std::size_t header = 0, dots = 0, line = 1;
  bool line_is_header = false, line_started = false, in_value = false;
  const auto end_line = [&] {
    const std::size_t depth = line_is_header ? dots + 1 : (line_started ? header + dots + 1 : 0);
    if (line_is_header) header = dots + 1;
    if (depth > deepest.depth) deepest = {depth, line};
    dots = 0, line_is_header = false, line_started = false, in_value = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      end_line();
      ++line;
    } else if (c == '#') {
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {
      const std::size_t next = after_string(text, i);
      for (std::size_t j = i; j < next; ++j) line += text[j] == '\n' ? 1 : 0;
      i = next - 1;
      line_started = true;
    } else if (c == '.') {
      // A key's parts may be digits (`[0.0.0]`); after `=`, a dot between digits is a number's.
      if (!in_value || !(i > 0 && digit_at(text, i - 1) && digit_at(text, i + 1))) ++dots;
    } else if (!std::isspace(static_cast<unsigned char>(c))) {
      if (!line_started && c == '[') line_is_header = true;
      if (c == '=' && !line_is_header) in_value = true;
      line_started = true;
    }
  }
  end_line();
  return deepest;
}

std::string toml_depth_problem(const TomlDepth& d) {
  if (d.depth <= kTomlDepthLimit) return {};
  return "keys nest tables " + std::to_string(d.depth) + " deep, past the " + std::to_string(kTomlDepthLimit) + " levels matbake reads";
}

}  // namespace matbake
