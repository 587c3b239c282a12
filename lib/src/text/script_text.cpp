#include "matbake/script_text.hpp"

#include <algorithm>
#include <cctype>

namespace matbake {

std::string unscriptable(std::string_view text) {
  if (text.find('\0') != std::string_view::npos) return "holds a NUL byte";
  if (text.find_first_of("\n\r") != std::string_view::npos) return "holds a line break";
  return {};
}

std::string shell_word(std::string_view word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("_./:=%@+,-").find(c) != std::string_view::npos;
  });
  if (plain) return std::string(word);
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

Result<std::string> ninja_path(std::string_view path) {
  std::string problem = unscriptable(path);
  if (problem.empty() && path.find('|') != std::string_view::npos) problem = "holds '|', which Ninja cannot escape in a path";
  if (!problem.empty()) return Error{std::string(path), problem + "; rename it to build it through Ninja", true};
  std::string out;
  for (char c : path) {
    if (c == '$' || c == ' ' || c == ':') out += '$';
    out += c;
  }
  return out;
}

std::string ninja_value(std::string_view value) {
  std::string out;
  for (char c : value) {
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

Result<std::string> depfile_path(std::string_view path) {
  // Ninja's depfile reader (depfile_parser.in.cc): these characters are a path's own; ' ', '#'
  // and '$' have escapes; anything else ends the path.
  const auto plain = [](unsigned char c) {
    return std::isalnum(c) || c >= 0x80 || std::string_view("+,/_:.~()}{%=@[]!-").find(char(c)) != std::string_view::npos;
  };
  std::string out;
  for (char c : path) {
    if (c == ' ' || c == '#') {
      out += '\\';
    } else if (c == '$') {
      out += '$';
    } else if (!plain(static_cast<unsigned char>(c))) {
      const std::string shown = c == '\n' ? "a line break" : c == '\t' ? "a tab" : c == '\0' ? "a NUL byte" : "'" + std::string(1, c) + "'";
      return Error{std::string(path), "holds " + shown + ", which a depfile (as Ninja reads it) cannot hold; rename it to build it through Ninja or CMake", true};
    }
    out += c;
  }
  if (!path.empty() && path.back() == ':') return Error{std::string(path), "ends with ':', which a depfile reads as a target", true};
  return out;
}

}  // namespace matbake
