#include "toml_value.hpp"

#include <charconv>

namespace matbake::params {

Result<Value> toml_value(const toml::node& node) {
  if (auto b = node.value_exact<bool>()) return Value(*b);
  // Integers only from integer nodes: toml++ 3.3 converts a float by a cast that is undefined
  // beyond the integer's range (found by fuzzing: samples = 2e52).
  if (node.is_integer()) return Value(*node.value<std::int64_t>());
  if (auto d = node.value_exact<double>()) return Value(*d);
  if (auto text = node.value_exact<std::string>()) return Value(*text);
  // A list of names (maps = ["normal", "ao"]) as the command line's comma-separated text.
  if (const toml::array* list = node.as_array(); list && !list->empty()) {
    std::string joined;
    for (const toml::node& item : *list) {
      auto name = item.value_exact<std::string>();
      if (!name || name->empty() || name->find(',') != std::string::npos) break;
      joined += (joined.empty() ? "" : ",") + *name;
      if (&item == &list->back()) return Value(joined);
    }
  }
  // A table of numbers by name ({ bolt = 0.4, plate = 0.02 }) as the command line's
  // "bolt=0.4,plate=0.02".
  if (const toml::table* table = node.as_table(); table && !table->empty()) {
    std::string joined;
    for (const auto& [key, value] : *table) {
      const std::string_view name = key.str();
      const auto number = value.is_integer() ? std::optional<double>(double(*value.value<std::int64_t>())) : value.value_exact<double>();
      if (!number || name.empty() || name.find_first_of(",=") != std::string_view::npos) {
        return Error{"", "a table of numbers by name expected ({ name = 0.5 }; names without ',' or '=')"};
      }
      char text[32];
      const auto written = std::to_chars(text, text + sizeof text, *number);
      if (!joined.empty()) joined += ',';
      joined += name;
      joined += '=';
      joined.append(text, written.ptr);
    }
    return Value(joined);
  }
  if (node.is_table()) return Error{"", "a table of numbers by name expected, not an empty one"};
  return Error{"", "a number, a string, a list of names, a table of numbers or true/false expected"};
}

}  // namespace matbake::params
