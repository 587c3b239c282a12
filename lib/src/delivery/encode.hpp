#pragma once
// A texture's levels through basisu: UASTC level by level (each level an 8-bit PNG in, one KTX2 of
// one level out, its blocks taken), assembled by ktx2::write_uastc; ETC1S in one run from level 0,
// basisu making the mips (its BasisLZ codebooks span every level, so given levels cannot be joined).
#include <filesystem>
#include <vector>

#include "basisu.hpp"
#include "matbake/delivery.hpp"

namespace matbake::delivery {

struct EncodeRequest {
  TextureClass texture_class = TextureClass::colour;
  ClassOptions options;
  Sampling sampling;            // ETC1S: basisu's own mip filter and edges
  bool mipmaps = true;          // ETC1S: basisu makes the chain
  bool alpha = false;           // RGBA, else RGB (has_alpha)
  std::filesystem::path scratch;  // a file name in the output folder: scratch files go beside it,
                                  // in the process's temporary folder (removed on an interrupt)
  int threads = 1;              // encoder threads (basisu -max_threads)
};

// Whether a texture needs its alpha: it has an alpha channel with a texel below 1 in 8 bits.
bool has_alpha(const image::Image& im);

// The UASTC blocks of one level (16 bytes per 4 × 4 block, rows of blocks top first).
Result<std::vector<unsigned char>> encode_uastc_level(const Encoder& encoder, const image::Image& level,
                                                      const EncodeRequest& request);
// A whole ETC1S KTX2 file from level 0, as basisu writes it.
Result<std::vector<unsigned char>> encode_etc1s(const Encoder& encoder, const image::Image& base, const EncodeRequest& request);

// basisu's arguments for a class's codec settings, without files (for stamps and the docs too).
std::vector<std::string> encoder_arguments(const EncodeRequest& request);

}  // namespace matbake::delivery
