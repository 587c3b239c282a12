#pragma once
// The parameters of image::Encoding: --png-compression and a manifest's png_compression.
#include "matbake/image.hpp"
#include "matbake/params.hpp"

namespace matbake::image {

const params::Group<Encoding>& encoding_params();

}  // namespace matbake::image
