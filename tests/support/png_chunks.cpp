#include "png_chunks.hpp"

#include <zlib.h>

namespace matbake::test {

std::string be32(std::uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

std::string png_chunk(const std::string& type, const std::string& data) {
  const std::string body = type + data;
  return be32(std::uint32_t(data.size())) + body +
         be32(std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
}

std::string png_ihdr(std::uint32_t w, std::uint32_t h, int depth, int colour_type, int interlace) {
  return png_chunk("IHDR", be32(w) + be32(h) + std::string{char(depth), char(colour_type), 0, 0, char(interlace)});
}

std::string deflated(const std::string& raw) {
  uLongf size = compressBound(uLong(raw.size()));
  std::string out(size, '\0');
  compress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()));
  out.resize(size);
  return out;
}

}  // namespace matbake::test
