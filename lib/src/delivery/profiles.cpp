#include "profiles.hpp"

#include <toml++/toml.h>

#include <algorithm>

#include "../params/toml_value.hpp"
#include "matbake/delivery_params.hpp"

namespace matbake::delivery {

std::vector<std::string> profile_names() {
  std::vector<std::string> names;
  for (const BuiltinProfile& p : builtin_profiles()) names.emplace_back(p.name);
  std::sort(names.begin(), names.end());
  return names;
}

std::optional<std::string> apply_profile(Options& options, const std::string& name) {
  const auto profile = std::find_if(builtin_profiles().begin(), builtin_profiles().end(), [&](auto& p) { return p.name == name; });
  if (profile == builtin_profiles().end()) return "no delivery profile '" + name + "'";
  const std::string where = "presets/delivery/" + name + ".toml";
  toml::table table;
  try {
    table = toml::parse(profile->text, where);
  } catch (const toml::parse_error& e) {
    return where + ": " + std::string(e.description());
  }
  const params::Group<Options>& group = options_params();
  for (const auto& [key, value] : table) {
    const params::Param<Options>* param = group.find(key.str());
    if (param == nullptr || param->spec.name == "delivery_profile") return where + ": '" + std::string(key.str()) + "' is not a delivery parameter";
    auto v = params::toml_value(value);
    std::optional<std::string> problem = v ? params::apply(*param, options, *v) : v.error().message;
    if (problem) return where + ": " + std::string(key.str()) + ": " + *problem;
  }
  options.profile = name;
  return std::nullopt;
}

}  // namespace matbake::delivery
