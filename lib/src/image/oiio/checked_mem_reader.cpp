// OIIO 2.4's (Debian's 2.4.7) in-memory reader trusts offsets taken from the file and reads out
// of bounds; found by tests/fuzz/fuzz_image, fixed upstream in later releases.
#include "checked_mem_reader.hpp"

#include <algorithm>
#include <cstring>

namespace matbake::image {

std::size_t CheckedMemReader::pread(void* buf, std::size_t size, std::int64_t offset) {
  const auto bytes = buffer();
  const auto length = std::int64_t(bytes.size());
  if (offset < 0 || offset >= length) return 0;
  size = std::min(size, std::size_t(length - offset));
  std::memcpy(buf, bytes.data() + offset, size);
  return size;
}

std::size_t CheckedMemReader::read(void* buf, std::size_t size) {
  const std::size_t got = pread(buf, size, m_pos);
  m_pos += std::int64_t(got);
  return got;
}

}  // namespace matbake::image
