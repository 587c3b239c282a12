// PNG read by libspng: every colour type and bit depth, interlaced or not, as OIIO's reader
// delivers it (bit depths below 8 scaled to 8, palettes to RGB, tRNS to an alpha channel, 16-bit
// kept), so results do not depend on which reader ran. Non-interlaced files are decoded row by
// row as bands are asked for; interlaced ones whole on the first band.
#pragma once

#include <cstdio>
#include <memory>
#include <span>
#include <string>

#include "stored_codec.hpp"

namespace matbake::image {

// The 8-byte PNG signature starts `bytes`.
bool has_png_signature(std::span<const unsigned char> bytes);

// `name` names the image in errors; `memory`, when not empty, holds its bytes (and must outlive
// the reader), else the file at `name` is read.
Result<std::unique_ptr<StoredReader>> open_png(const std::string& name, std::span<const unsigned char> memory);

}  // namespace matbake::image
