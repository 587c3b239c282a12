#pragma once
// The one gate for what a build writes outside its jobs' own outputs and for everything it deletes
// (docs/reliability.md, "What matbake writes, deletes and runs"). It knows the output folder's real
// path and the files the run must never touch (its inputs, and the outputs its jobs make now), by
// device and inode, so no name — a link, `..`, `./`, a hard link — reaches them another way.
//
// Deletes walk the recorded path one folder at a time from the output folder's descriptor with
// O_NOFOLLOW (openat), so a link planted anywhere on the way is refused, not followed.
#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <utility>

#include "matbake/result.hpp"

namespace matbake {

// XXH64 of a file's bytes as 16 hex digits, read in fixed-size blocks (constant memory, whatever its
// size); empty when it cannot be read. From an open descriptor, so the bytes hashed are the file
// opened and checked, not whatever the name points at a moment later.
std::string hash_file_descriptor(int fd);
std::string hash_bytes(std::span<const unsigned char> bytes);

enum class RemoveOutcome { removed, changed, missing, refused };

struct RemoveResult {
  RemoveOutcome outcome = RemoveOutcome::missing;
  std::string why;  // refused: the reason, for the warning
};

class RealPaths;

// One thread at a time: it remembers the real paths it has resolved.
class OutputGate {
 public:
  // `folder` need not exist yet (a first run); `protect` are the files no write or delete may touch.
  OutputGate(const std::filesystem::path& folder, std::span<const std::filesystem::path> protect);
  ~OutputGate();
  OutputGate(OutputGate&&) noexcept;

  const std::filesystem::path& real_folder() const { return real_folder_; }

  // Whether `file`'s real path is inside the output folder's (no link leads out of it).
  bool holds(const std::filesystem::path& file) const;

  // A file written beside the outputs on a user's request (--depfile, --stamp, plan -o, a Slurm
  // folder): anywhere but never a protected file, nor inside the output folder's state folder
  // (.matbake). Errors are usage errors naming `option` and the file.
  Status check_side_output(const std::filesystem::path& target, const std::string& option) const;

  // Removes `recorded` (a path relative to the output folder, as made.json holds it) only when it
  // provably is the file matbake made: written in normal form (no `..`, `.`, empty or absolute
  // part), below the folder through real folders only, a regular file, not protected, outside
  // .matbake, and with the recorded hash now.
  RemoveResult remove_made(const std::string& recorded, const std::string& hash, bool dry_run) const;

  // Whether `file` is a protected file, however it is named.
  bool is_protected(const std::filesystem::path& file) const;

 private:
  std::unique_ptr<RealPaths> real_;
  std::filesystem::path folder_;
  std::filesystem::path real_folder_;
  std::set<std::pair<dev_t, ino_t>> protected_;   // those that exist, by identity
  std::set<std::string> protected_real_;           // all, by real path (outputs not written yet)
};

// Why `recorded` is not a path made.json may hold, or empty when it is one.
std::string recorded_path_problem(const std::string& recorded);

}  // namespace matbake
