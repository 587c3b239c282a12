#pragma once
// A parameter's example value as a manifest writes it (the flag takes the example's text as is).
#include <regex>
#include <string>

#include "matbake/params.hpp"

namespace matbake::test {

inline std::string toml_literal(const params::Spec& spec) {
  using params::Kind;
  if (spec.kind == Kind::flag || spec.kind == Kind::integer || spec.kind == Kind::number) return spec.example;
  if (spec.kind == Kind::integer_or_text && std::regex_match(spec.example, std::regex("[0-9]+"))) return spec.example;
  return "\"" + spec.example + "\"";
}

}  // namespace matbake::test
