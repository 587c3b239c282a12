#pragma once
// A TOML value as a parameter takes it (params::accept then checks its kind): the manifest's keys and
// the delivery profiles' (presets/delivery/*.toml) are read through this one function.
#include <toml++/toml.h>

#include "matbake/params.hpp"
#include "matbake/result.hpp"

namespace matbake::params {

Result<Value> toml_value(const toml::node& node);

}  // namespace matbake::params
