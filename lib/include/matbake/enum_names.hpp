#pragma once
// Option enums and the names both front ends (command line, manifest) use for them: each module
// keeps one table per enum, and its `<enum>_name` / `<enum>_from_name` read that table only.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace matbake {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<E, std::string_view>, N>;

template <class E, std::size_t N>
constexpr std::string_view name_in(const NameTable<E, N>& table, E value) {
  for (const auto& [v, name] : table) {
    if (v == value) return name;
  }
  return "?";
}

template <class E, std::size_t N>
constexpr std::optional<E> value_in(const NameTable<E, N>& table, std::string_view name) {
  for (const auto& [v, n] : table) {
    if (n == name) return v;
  }
  return std::nullopt;
}

// "a, b or c": for messages that list what is accepted.
template <class E, std::size_t N>
std::string names_in(const NameTable<E, N>& table) {
  std::string out;
  for (std::size_t i = 0; i < N; ++i) {
    out += (i == 0 ? "" : i + 1 == N ? " or " : ", ") + std::string(table[i].second);
  }
  return out;
}

}  // namespace matbake
