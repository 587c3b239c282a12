#pragma once
// The parameters of image::Encoding: --png-compression and a manifest's png_compression, and for
// glTF outputs the texture format.
#include "matbake/image.hpp"
#include "matbake/params.hpp"

namespace matbake::image {

const params::Group<Encoding>& encoding_params();
// The format of the textures a glTF gets (export, bake-ao --texture, a manifest's scenes):
// --texture-format and a scene's texture_format.
const params::Group<Encoding>& gltf_texture_params();

}  // namespace matbake::image
