// PNG files made chunk by chunk, so that a test's damage to one is exact.
#pragma once

#include <cstdint>
#include <string>

namespace matbake::test {

inline const std::string kPngSignature("\x89PNG\r\n\x1a\n", 8);

std::string be32(std::uint32_t v);
// A chunk: its length, type, data and CRC.
std::string png_chunk(const std::string& type, const std::string& data);
std::string png_ihdr(std::uint32_t w, std::uint32_t h, int depth, int colour_type, int interlace = 0);
// zlib's stream of `raw` (filtered rows), as IDAT holds it.
std::string deflated(const std::string& raw);

}  // namespace matbake::test
