#pragma once
// Outputs are written to a temporary file in the target's folder and renamed over the target only
// when complete, so a failure leaves nothing half-written and never touches an existing output.
#include <filesystem>
#include <span>
#include <string_view>

#include "matbake/result.hpp"

namespace matbake {

class AtomicFile {
 public:
  // Makes the target's folder when it is missing (every output of every command); fails when it
  // cannot be made or is not writable.
  static Result<AtomicFile> create(const std::filesystem::path& target);

  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&&) = delete;
  AtomicFile(const AtomicFile&) = delete;
  ~AtomicFile();  // removes the temporary file unless committed

  // Same folder and extension as the target (writers pick their format by extension).
  const std::filesystem::path& temp_path() const { return temp_; }
  Status commit();

 private:
  AtomicFile(std::filesystem::path target, std::filesystem::path temp);
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool done_ = false;
};

// The whole of `bytes` as `target`, through a temporary file and a rename.
Status write_file_atomically(const std::filesystem::path& target, std::string_view bytes);
// The parts one after the other (a large file written without assembling it in memory first).
Status write_file_atomically(const std::filesystem::path& target, std::span<const std::string_view> parts);

// Removes `path` whatever it is: a file, a link (removed, never followed), a folder with all it
// holds. For what a program matbake ran left in a temporary folder under a name matbake gave it (an
// encoder that made a folder where its output file should be kept the folder for good).
void remove_program_output(const std::filesystem::path& path);

// Removes every temporary file an AtomicFile of this process holds now, and keeps new ones from
// being made (create() fails from then on): for a SIGINT/SIGTERM handler that is about to _exit,
// so that an interrupted run leaves its finished outputs and no temporary files. Call it from a
// normal thread (one waiting in sigwait), not from an asynchronous signal handler: it takes a lock.
void remove_temporary_files_for_exit();

}  // namespace matbake
