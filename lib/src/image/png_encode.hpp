#pragma once
// 8- and 16-bit PNG written with libdeflate instead of OIIO's libpng + zlib: the same row filters
// (chosen per row as libpng does), a deflate stream several times faster than zlib's at the same
// size (docs/performance.md). Rows come in bands, in order; finish() compresses and frames.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/image.hpp"

namespace matbake::image {

class PngEncoder {
 public:
  // `bits` 8 or 16; `level` libdeflate's 0 (stored) to 12; `colorspace` as WriteOptions has it.
  PngEncoder(const ImageLayout& layout, int bits, int level, std::string_view colorspace);

  // The next rows, as samples of the file's width (uint8_t for 8 bits, uint16_t for 16).
  void add_rows(std::span<const std::uint8_t> samples);
  void add_rows(std::span<const std::uint16_t> samples);

  // The whole file. Call once, after every row.
  std::string finish();

 private:
  void filter_row(const std::uint8_t* row);

  int width_, height_, channels_, bits_, level_;
  std::string colorspace_;
  std::size_t row_bytes_;   // unfiltered bytes of one row
  std::size_t pixel_bytes_; // the distance filters look back
  std::vector<std::uint8_t> filtered_;  // filter byte + filtered row, per row so far
  std::vector<std::uint8_t> previous_, current_;  // raw rows, for the filters (Up, Average, Paeth)
  std::vector<std::uint8_t> candidate_;  // one filtered row per filter type
};

}  // namespace matbake::image
