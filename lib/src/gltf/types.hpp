#pragma once
// The JSON type of every core glTF 2.0 property matbake reads or passes through, checked when a file
// is read: a material whose pbrMetallicRoughness is a number was copied into outputs the validator
// rejects (TYPE_MISMATCH), or threw from a reader expecting an object. Also each enumeration's values
// (alphaMode, componentType, a sampler's filters, ...) and each fixed-length array's length
// (baseColorFactor 4, matrix 16, ...). Extensions' contents and extras are not the core's: not checked.
#include <string>

#include "document.hpp"

namespace matbake::gltf {

// The first property of the wrong type, length or value, with its JSON pointer:
// "/materials/0/pbrMetallicRoughness: 3 is not an object".
Status check_types(const std::string& file, const Json& json);

}  // namespace matbake::gltf
