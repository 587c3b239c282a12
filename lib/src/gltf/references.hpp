#pragma once
// Every index a glTF object holds, checked against the array it points into before anything is read
// or written: a material's texture past `textures` would otherwise be written into a file the
// validator rejects (INVALID_INDEX). Errors name the JSON pointer of the bad index.
#include <string>

#include "document.hpp"

namespace matbake::gltf {

// Scene, nodes (camera, skin, mesh, children, instancing attributes, light), meshes (indices,
// attributes, morph targets, material, Draco view, variant mappings), materials (every `...Texture`
// index, core and extensions), textures (sampler, source and extensions' sources), images, accessors
// (view, sparse views), buffer views (buffer, meshopt's buffer), skins and animations.
// "/materials/0/occlusionTexture/index: texture 99 does not exist (the file has 1)".
Status check_references(const std::string& file, const Json& json);

}  // namespace matbake::gltf
