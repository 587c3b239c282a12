#pragma once
// Whole files in one read (a size, one allocation, one copy): glTF files and their buffers, stamps
// and manifests are read this way, never byte by byte.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>

namespace matbake {

// `out` (a std::string or std::vector of bytes) becomes the file's bytes; false when it cannot be
// read or is not a regular file (a folder opens as a stream of "infinite" size; a FIFO or a device
// never ends). open, fstat, read, close: a build's no-op run reads thousands of stamps.
template <class Bytes>
bool read_whole_file(const std::filesystem::path& path, Bytes& out) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);  // a FIFO does not block the open
  if (fd < 0) return false;
  struct stat s;
  bool ok = ::fstat(fd, &s) == 0 && S_ISREG(s.st_mode);
  if (ok) {
    out.resize(std::size_t(s.st_size));
    std::size_t done = 0;
    while (ok && done < out.size()) {
      const ssize_t n = ::read(fd, reinterpret_cast<char*>(out.data()) + done, out.size() - done);
      if (n > 0) {
        done += std::size_t(n);
      } else if (n == 0) {
        out.resize(done);  // shorter than its size said (truncated meanwhile): what is there
        break;
      } else {
        ok = errno == EINTR;
      }
    }
  }
  ::close(fd);
  return ok;
}

}  // namespace matbake
