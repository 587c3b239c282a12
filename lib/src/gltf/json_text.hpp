// The JSON text matbake writes a glTF as.
#pragma once

#include <string>

#include "document.hpp"

namespace matbake::gltf {

// `json` as text, as nlohmann's dump(indent) writes it but for numbers: each floating-point number
// in the shortest form that reads back as itself, as a float32 where it is one (runtimes read
// float32: 6.103888e-05, not 6.103888176768602e-05), and whole numbers without ".0".
// Non-finite numbers, which JSON cannot hold, are null as in dump.
std::string json_text(const Json& json, int indent = -1);

}  // namespace matbake::gltf
