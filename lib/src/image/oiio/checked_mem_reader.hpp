// OIIO 2.4's in-memory reader with its offsets checked (checked_mem_reader.cpp).
#pragma once

#include <OpenImageIO/filesystem.h>

#include <cstddef>
#include <cstdint>

namespace matbake::image {

// An image in memory for OIIO. OIIO 2.4's IOMemReader::pread checks `offset + size` after it
// wraps, so a position taken from the file (an EXR line offset of -5) reads before the buffer.
class CheckedMemReader final : public OIIO::Filesystem::IOMemReader {
 public:
  using IOMemReader::IOMemReader;
  std::size_t pread(void* buf, std::size_t size, std::int64_t offset) override;
  std::size_t read(void* buf, std::size_t size) override;
};

}  // namespace matbake::image
