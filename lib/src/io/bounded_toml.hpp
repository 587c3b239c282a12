#pragma once
// TOML that matbake reads (manifests, material tables) passes a depth check before toml++ sees it.
// toml++ bounds inline arrays and tables itself (TOML_MAX_NESTED_VALUES, 256), but not tables named
// by dotted keys and headers, and it frees tables recursively: a 600 KB manifest whose header names
// a table 300,000 deep ended `build` with SIGSEGV.
#include <cstddef>
#include <string>
#include <string_view>

namespace matbake {

inline constexpr std::size_t kTomlDepthLimit = 256;

struct TomlDepth {
  std::size_t depth = 0;  // the most tables a key reaches through: its header's parts and its own
  std::size_t line = 0;   // where (1-based), 0 in an empty text
};

// Counted by one linear pass: the dots of every key outside strings and comments (after `=`, a dot
// between two digits is a number's), a header's parts carried to the keys below it.
TomlDepth toml_key_depth(std::string_view text);

// Why a text of depth `d` may not be parsed (its keys nest past kTomlDepthLimit; d.line says
// where); empty when it may be.
std::string toml_depth_problem(const TomlDepth& d);

}  // namespace matbake
