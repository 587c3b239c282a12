#pragma once
// The delivery profiles of presets/delivery/ (web, mobile, desktop, archive), compiled in
// (generated builtin_profiles.cpp) so that an installed matbake has them: each a TOML table of
// delivery parameters, set by `delivery_profile` before any parameter given beside it.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/delivery.hpp"

namespace matbake::delivery {

struct BuiltinProfile {
  std::string_view name;  // the file's stem
  std::string_view text;  // its TOML
};
std::span<const BuiltinProfile> builtin_profiles();

// The profiles' names, sorted.
std::vector<std::string> profile_names();

// `options` with every value profile `name` sets (each checked as its parameter checks a manifest's
// value) and `options.profile` = name; the problem, naming the profile's key, when one is refused.
std::optional<std::string> apply_profile(Options& options, const std::string& name);

}  // namespace matbake::delivery
