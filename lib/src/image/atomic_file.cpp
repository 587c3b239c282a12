#include "matbake/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace matbake {

AtomicFile::AtomicFile(fs::path target, fs::path temp) : target_(std::move(target)), temp_(std::move(temp)) {}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : target_(std::move(other.target_)), temp_(std::move(other.temp_)), done_(other.done_) {
  other.done_ = true;
}

AtomicFile::~AtomicFile() {
  if (!done_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

Result<AtomicFile> AtomicFile::create(const fs::path& target) {
  std::error_code ec;
  if (fs::is_directory(target, ec)) return Error{target.string(), "is a folder, not a file"};
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, ec)) return Error{target.string(), "output folder does not exist"};

  // Hidden, unique within the process and across processes, same extension as the target.
  static std::atomic<unsigned> counter{0};
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path temp = folder / ("." + target.stem().string() + ".matbake-" + std::to_string(getpid()) + "-" +
                                    std::to_string(counter++) + target.extension().string());
    // Creating it reserves the name and tells, with the real reason, whether the folder takes files.
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd >= 0) {
      ::close(fd);
      return AtomicFile(target, temp);
    }
    if (errno != EEXIST) {
      return Error{target.string(), std::string("cannot write in the output folder: ") + std::strerror(errno)};
    }
  }
  return Error{target.string(), "cannot find a free temporary name in the output folder"};
}

Status AtomicFile::commit() {
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) return Error{target_.string(), "cannot replace the output: " + ec.message()};
  done_ = true;
  return success();
}

Status write_file_atomically(const fs::path& target, std::string_view bytes) {
  auto file = AtomicFile::create(target);
  if (!file) return file.error();
  {
    std::ofstream out(file->temp_path(), std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out.flush()) return Error{target.string(), "cannot write"};
  }
  return file->commit();
}

}  // namespace matbake
