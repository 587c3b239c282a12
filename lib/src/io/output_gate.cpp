#include "matbake/output_gate.hpp"

#include "real_paths.hpp"
#include "unique_fd.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <memory>
#include <vector>

namespace matbake {
namespace fs = std::filesystem;
namespace {

constexpr const char* kStateFolder = ".matbake";

using Fd = UniqueFd;

std::string hex(XXH64_hash_t h) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", (unsigned long long)h);
  return text;
}

bool inside(const fs::path& folder, const fs::path& path) {
  const auto [f, p] = std::mismatch(folder.begin(), folder.end(), path.begin(), path.end());
  return f == folder.end();
}

}  // namespace

std::string hash_bytes(std::span<const unsigned char> bytes) { return hex(XXH64(bytes.data(), bytes.size(), 0)); }

std::string hash_file_descriptor(int fd) {
  const std::unique_ptr<XXH64_state_t, decltype(&XXH64_freeState)> state(XXH64_createState(), XXH64_freeState);
  if (!state || XXH64_reset(state.get(), 0) == XXH_ERROR) return {};
  std::vector<char> block(1 << 20);
  for (;;) {
    const ssize_t n = ::read(fd, block.data(), block.size());
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      return {};
    }
    XXH64_update(state.get(), block.data(), std::size_t(n));
  }
  return hex(XXH64_digest(state.get()));
}

std::string recorded_path_problem(const std::string& recorded) {
  if (recorded.empty()) return "an empty path";
  if (recorded.find('\0') != std::string::npos) return "a NUL byte in the path";
  if (recorded.front() == '/') return "an absolute path";
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = recorded.find('/', start);
    const std::string part = recorded.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part.empty() || part == "." || part == "..") return "not a plain path below the output folder ('" + part + "' part)";
    if (start == 0 && part == kStateFolder) return "inside matbake's state folder";
    if (end == std::string::npos) return {};
    start = end + 1;
  }
}

OutputGate::OutputGate(const fs::path& folder, std::span<const fs::path> protect)
    : real_(std::make_unique<RealPaths>()), folder_(fs::absolute(folder).lexically_normal()), real_folder_(real_->of(folder)) {
  for (const fs::path& p : protect) {
    struct stat s;
    if (::stat(p.c_str(), &s) == 0) protected_.insert({s.st_dev, s.st_ino});
    protected_real_.insert(real_->of(p).native());
  }
}

OutputGate::~OutputGate() = default;
OutputGate::OutputGate(OutputGate&&) noexcept = default;

bool OutputGate::holds(const fs::path& file) const { return real_->inside(real_folder_, file); }

bool OutputGate::is_protected(const fs::path& file) const {
  struct stat s;
  if (::stat(file.c_str(), &s) == 0 && protected_.count({s.st_dev, s.st_ino})) return true;
  return protected_real_.count(real_->of(file).native()) > 0;
}

Status OutputGate::check_side_output(const fs::path& target, const std::string& option) const {
  const std::string name = option + " " + target.string();
  std::error_code ec;
  if (fs::is_directory(target, ec)) return Error{name, "is a folder, not a file", true};
  if (is_protected(target)) {
    return Error{name, "is a file this build reads or writes (the manifest, a source or an output); matbake never overwrites it", true};
  }
  // The state folder holds matbake's stamps, logs and locks (.json, .failed, .lock); the depfiles of
  // its own Ninja plan (.d) live there too.
  if (inside(real_folder_ / kStateFolder, real_->of(target)) && target.extension() != ".d") {
    return Error{name, "is inside the output folder's state folder (.matbake), which only matbake writes", true};
  }
  return success();
}

RemoveResult OutputGate::remove_made(const std::string& recorded, const std::string& hash, bool dry_run) const {
  if (const std::string problem = recorded_path_problem(recorded); !problem.empty()) return {RemoveOutcome::refused, problem};
  std::vector<std::string> parts;
  for (const auto& part : fs::path(recorded)) parts.push_back(part.string());
  auto dir = std::make_unique<Fd>(::open(real_folder_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir->fd < 0) return {RemoveOutcome::missing, {}};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    auto next = std::make_unique<Fd>(::openat(dir->fd, parts[i].c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
    if (next->fd < 0) {
      if (errno == ENOENT) return {RemoveOutcome::missing, {}};
      return {RemoveOutcome::refused, "'" + parts[i] + "' is not a real folder (a link, or unreadable)"};
    }
    dir = std::move(next);
  }
  const std::string& name = parts.back();
  const Fd file(::openat(dir->fd, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC));
  if (file.fd < 0) {
    if (errno == ENOENT) return {RemoveOutcome::missing, {}};
    return {RemoveOutcome::refused, errno == ELOOP ? "a link, not the file matbake made" : "cannot be opened"};
  }
  struct stat s;
  if (::fstat(file.fd, &s) != 0 || !S_ISREG(s.st_mode)) return {RemoveOutcome::refused, "not a regular file"};
  if (protected_.count({s.st_dev, s.st_ino})) return {RemoveOutcome::refused, "it is an input or a current output"};
  if (hash_file_descriptor(file.fd) != hash) return {RemoveOutcome::changed, {}};
  if (dry_run) return {RemoveOutcome::removed, {}};
  // The name must still be the file just checked (not swapped for another meanwhile).
  struct stat again;
  if (::fstatat(dir->fd, name.c_str(), &again, AT_SYMLINK_NOFOLLOW) != 0 || again.st_dev != s.st_dev || again.st_ino != s.st_ino) {
    return {RemoveOutcome::changed, {}};
  }
  if (::unlinkat(dir->fd, name.c_str(), 0) != 0) return {RemoveOutcome::refused, "cannot be removed"};
  return {RemoveOutcome::removed, {}};
}

}  // namespace matbake
