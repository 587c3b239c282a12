#include "toml_value.hpp"

namespace matbake::params {

Result<Value> toml_value(const toml::node& node) {
  if (auto b = node.value_exact<bool>()) return Value(*b);
  // Integers only from integer nodes: toml++ 3.3 converts a float by a cast that is undefined
  // beyond the integer's range (found by fuzzing: samples = 2e52).
  if (node.is_integer()) return Value(*node.value<std::int64_t>());
  if (auto d = node.value_exact<double>()) return Value(*d);
  if (auto text = node.value_exact<std::string>()) return Value(*text);
  return Error{"", "a number, a string or true/false expected"};
}

}  // namespace matbake::params
