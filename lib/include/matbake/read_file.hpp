#pragma once
// Whole files in one read (a size, one allocation, one copy): glTF files and their buffers are read
// this way, never byte by byte.
#include <filesystem>
#include <fstream>

namespace matbake {

// `out` (a std::string or std::vector of bytes) becomes the file's bytes; false when it cannot be
// read or is not a regular file (a folder opens as a stream of "infinite" size; a FIFO or a device
// never ends).
template <class Bytes>
bool read_whole_file(const std::filesystem::path& path, Bytes& out) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return false;
  const std::streamoff size = in.tellg();
  if (size < 0) return false;
  out.resize(std::size_t(size));
  in.seekg(0);
  return size == 0 || bool(in.read(reinterpret_cast<char*>(out.data()), size));
}

}  // namespace matbake
