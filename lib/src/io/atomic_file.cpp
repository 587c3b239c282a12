#include "matbake/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>
#include <set>
#include <string>

namespace fs = std::filesystem;

namespace matbake {

namespace {

// The temporary files that exist now, for remove_temporary_files_for_exit(). A name is added before
// the file is made and taken out after it is renamed or removed, under one lock.
//
// They live in a hidden folder of this process's own in the target's folder (.matbake-PID), so that
// an interrupt can close them off for good: writers (ours, OIIO's) open their temporary file by
// name, and one that does so after the file was removed would make it again; once the folder is
// gone, no open can.
struct TemporaryFiles {
  std::mutex mutex;
  std::set<fs::path> paths;
  bool closed = false;
};
TemporaryFiles& temporary_files() {
  static TemporaryFiles files;
  return files;
}

fs::path temporary_folder_in(const fs::path& folder) { return folder / (".matbake-" + std::to_string(getpid())); }

// Under the lock: the folder goes when its last file does (another of ours may still be in it).
void forget_temporary(TemporaryFiles& files, const fs::path& temp) {
  files.paths.erase(temp);
  (void)::rmdir(temp.parent_path().c_str());
}

// Removes the folder even while writers make files in it: each pass removes what is there.
void remove_temporary_folder(const fs::path& folder) {
  for (int pass = 0; pass < 100; ++pass) {
    if (::rmdir(folder.c_str()) == 0 || errno == ENOENT) return;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) ::unlink(entry.path().c_str());
  }
}

// An existing name must be our folder, not a link planted to send outputs elsewhere.
Status make_temporary_folder(const fs::path& temp_folder, const fs::path& target) {
  if (::mkdir(temp_folder.c_str(), 0755) == 0) return success();
  const int mkdir_errno = errno;
  std::error_code ec;
  if (mkdir_errno == EEXIST && fs::symlink_status(temp_folder, ec).type() == fs::file_type::directory) return success();
  const std::string reason = mkdir_errno == EEXIST ? temp_folder.filename().string() + " is not a folder" : std::strerror(mkdir_errno);
  return Error{target.string(), "cannot write in the output folder: " + reason};
}

}  // namespace

void remove_temporary_files_for_exit() {
  TemporaryFiles& files = temporary_files();
  files.mutex.lock();  // held until the process exits: no file is made or renamed after this
  files.closed = true;
  std::set<fs::path> folders;
  for (const fs::path& p : files.paths) {
    ::unlink(p.c_str());
    folders.insert(p.parent_path());
  }
  for (const fs::path& folder : folders) remove_temporary_folder(folder);
}

AtomicFile::AtomicFile(fs::path target, fs::path temp) : target_(std::move(target)), temp_(std::move(temp)) {}

AtomicFile::AtomicFile(AtomicFile&& other) noexcept
    : target_(std::move(other.target_)), temp_(std::move(other.temp_)), done_(other.done_) {
  other.done_ = true;
}

AtomicFile::~AtomicFile() {
  if (!done_) {
    TemporaryFiles& files = temporary_files();
    std::lock_guard lock(files.mutex);
    ::unlink(temp_.c_str());
    forget_temporary(files, temp_);
  }
}

Result<AtomicFile> AtomicFile::create(const fs::path& target) {
  std::error_code ec;
  if (fs::is_directory(target, ec)) return Error{target.string(), "is a folder, not a file"};
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // The one rule for every output of every command: a missing folder is made (as mkdir -p does).
  if (!fs::is_directory(folder, ec)) {
    fs::create_directories(folder, ec);
    if (ec || !fs::is_directory(folder)) {
      return Error{target.string(), "cannot make the output folder: " + (ec ? ec.message() : "not a folder")};
    }
  }

  // Unique within the process and across processes, same extension as the target.
  static std::atomic<unsigned> counter{0};
  const fs::path temp_folder = temporary_folder_in(folder);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path temp = temp_folder / (target.stem().string() + "-" + std::to_string(counter++) + target.extension().string());
    // Creating it reserves the name and tells, with the real reason, whether the folder takes files.
    TemporaryFiles& files = temporary_files();
    std::unique_lock lock(files.mutex);
    if (files.closed) return Error{target.string(), "interrupted"};
    if (Status made = make_temporary_folder(temp_folder, target); !made) return made.error();
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    const int open_errno = errno;
    if (fd >= 0) {
      ::close(fd);
      files.paths.insert(temp);
      return AtomicFile(target, temp);
    }
    (void)::rmdir(temp_folder.c_str());  // when empty
    lock.unlock();
    if (open_errno != EEXIST) {
      return Error{target.string(), std::string("cannot write in the output folder: ") + std::strerror(open_errno)};
    }
  }
  return Error{target.string(), "cannot find a free temporary name in the output folder"};
}

Status AtomicFile::commit() {
  std::error_code ec;
  {
    // Under the lock, so that an interrupt sees either the temporary file or the renamed output.
    TemporaryFiles& files = temporary_files();
    std::lock_guard lock(files.mutex);
    fs::rename(temp_, target_, ec);
    if (!ec) forget_temporary(files, temp_);
  }
  if (ec) return Error{target_.string(), "cannot replace the output: " + ec.message()};
  done_ = true;
  return success();
}

Status write_file_atomically(const fs::path& target, std::string_view bytes) {
  return write_file_atomically(target, std::span<const std::string_view>(&bytes, 1));
}

Status write_file_atomically(const fs::path& target, std::span<const std::string_view> parts) {
  auto file = AtomicFile::create(target);
  if (!file) return file.error();
  {
    std::ofstream out(file->temp_path(), std::ios::binary);
    for (std::string_view bytes : parts) out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out.flush()) return Error{target.string(), "cannot write"};
  }
  return file->commit();
}

}  // namespace matbake
