#include "matbake/atomic_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace matbake {

namespace {

// The temporary files that exist now, for remove_temporary_files_for_exit(). A name is added before
// the file is made and taken out after it is renamed or removed, under one lock.
//
// They live in a hidden folder of this process's own in the target's folder, so that an interrupt
// can close them off for good: writers (ours, OIIO's) open their temporary file by name, and one
// that does so after the file was removed would make it again; once the folder is gone, no open
// can. The folder is named .matbake-tmp-HOST-PID-TOKEN (a random token: two processes with one PID
// on a shared filesystem, from two containers or nodes, never share one), made exclusively, and
// held under an flock while it exists, so that a later run can prove its owner gone.
struct TemporaryFiles {
  std::mutex mutex;
  std::set<fs::path> paths;
  std::map<fs::path, int> folders;  // made by this process, each with its locked descriptor
  std::set<fs::path> swept;         // target folders whose leftovers were looked at
  bool closed = false;
};
TemporaryFiles& temporary_files() {
  static TemporaryFiles files;
  return files;
}

constexpr const char* kPrefix = ".matbake-tmp-";
// A leftover folder of another host is removed only this long after its last change.
constexpr auto kLeftoverAge = std::chrono::hours(24);

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "host";
  std::string out;
  for (char c : std::string(name)) out += std::isalnum(static_cast<unsigned char>(c)) || c == '.' ? c : '_';
  return out;
}

const std::string& folder_name() {
  static const std::string name = [] {
    std::random_device random;
    char token[17];
    std::snprintf(token, sizeof token, "%08x%08x", random(), random());
    return kPrefix + host_name() + "-" + std::to_string(getpid()) + "-" + token;
  }();
  return name;
}

fs::path temporary_folder_in(const fs::path& folder) { return folder / folder_name(); }

// Whether a leftover folder's owner is provably gone: nobody holds its lock, and it is this host's
// with a PID that runs no process here, or it has not changed for kLeftoverAge.
bool owner_gone(int folder_fd, const std::string& name) {
  if (::flock(folder_fd, LOCK_EX | LOCK_NB) != 0) return false;
  const std::string host = kPrefix + host_name() + "-";
  if (name.rfind(host, 0) == 0) {
    const long pid = std::strtol(name.c_str() + host.size(), nullptr, 10);
    if (pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH) return true;
  }
  struct stat s;
  if (::fstat(folder_fd, &s) != 0) return false;
  const auto changed = std::chrono::system_clock::from_time_t(s.st_mtim.tv_sec);
  return std::chrono::system_clock::now() - changed > kLeftoverAge;
}

// Removes `name` in the folder `dir` (a descriptor, or AT_FDCWD) whatever it is: a file or a link is
// unlinked (never followed), a folder emptied the same way first, down to kMostDepth folders. A
// temporary folder may hold what a program it ran left there (an encoder that made a folder where
// its output file should be).
constexpr int kMostDepth = 64;
void remove_entry(int dir, const char* name, int depth) {
  if (::unlinkat(dir, name, 0) == 0 || errno != EISDIR || depth > kMostDepth) return;
  const int fd = ::openat(dir, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  DIR* folder = ::fdopendir(fd);
  if (folder == nullptr) {
    ::close(fd);
    return;
  }
  std::vector<std::string> names;
  while (const dirent* e = ::readdir(folder)) {
    if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) names.emplace_back(e->d_name);
  }
  for (const std::string& n : names) remove_entry(::dirfd(folder), n.c_str(), depth + 1);
  ::closedir(folder);
  ::unlinkat(dir, name, AT_REMOVEDIR);
}

// Removes the leftover temporary folders in `folder` whose owners are provably gone (a run killed
// with SIGKILL leaves one), whatever they hold. Nothing is followed (a link is removed as a link).
void sweep_leftovers(const fs::path& folder) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kPrefix, 0) != 0 || name == folder_name()) continue;
    const int fd = ::open(entry.path().c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) continue;
    if (owner_gone(fd, name)) remove_entry(AT_FDCWD, entry.path().c_str(), 0);
    ::close(fd);
  }
}

// Under the lock: the folder goes when its last file does (another of ours may still be in it).
void forget_temporary(TemporaryFiles& files, const fs::path& temp) {
  files.paths.erase(temp);
  const fs::path folder = temp.parent_path();
  if (::rmdir(folder.c_str()) == 0) {
    if (const auto found = files.folders.find(folder); found != files.folders.end()) {
      ::close(found->second);
      files.folders.erase(found);
    }
  }
}

// Removes the folder even while writers make files in it: each pass removes what is there.
void remove_temporary_folder(const fs::path& folder) {
  for (int pass = 0; pass < 100; ++pass) {
    if (::rmdir(folder.c_str()) == 0 || errno == ENOENT) return;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) remove_entry(AT_FDCWD, entry.path().c_str(), 0);
  }
}

// Under the lock: this process's folder in `target`'s folder, made exclusively (an existing name is
// never taken for ours: it may be a link planted to send outputs elsewhere) and locked.
Status make_temporary_folder(TemporaryFiles& files, const fs::path& temp_folder, const fs::path& target) {
  if (files.folders.count(temp_folder)) return success();
  if (files.swept.insert(temp_folder.parent_path()).second) sweep_leftovers(temp_folder.parent_path());
  if (::mkdir(temp_folder.c_str(), 0700) != 0) {
    const std::string reason = errno == EEXIST ? temp_folder.filename().string() + " exists and is not this run's" : std::strerror(errno);
    return Error{target.string(), "cannot write in the output folder: " + reason};
  }
  const int fd = ::open(temp_folder.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd >= 0) ::flock(fd, LOCK_EX | LOCK_NB);
  files.folders[temp_folder] = fd;
  return success();
}

}  // namespace

void remove_program_output(const fs::path& path) { remove_entry(AT_FDCWD, path.c_str(), 0); }

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
    if (Status made = make_temporary_folder(files, temp_folder, target); !made) return made.error();
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    const int open_errno = errno;
    if (fd >= 0) {
      ::close(fd);
      files.paths.insert(temp);
      return AtomicFile(target, temp);
    }
    forget_temporary(files, temp);  // the folder, when empty
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
