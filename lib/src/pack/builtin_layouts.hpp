#pragma once
// The layouts of presets/layouts/, compiled in (generated builtin_layouts.cpp) so that the library
// works without knowing where presets/ was installed.
#include <span>
#include <string_view>

namespace matbake::pack {

struct BuiltinLayout {
  std::string_view name;
  std::string_view json;
};
std::span<const BuiltinLayout> builtin_layouts();

}  // namespace matbake::pack
