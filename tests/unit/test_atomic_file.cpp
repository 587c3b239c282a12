// Outputs through a temporary file and a rename; an interrupt leaves finished files and no temporary ones.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "matbake/atomic_file.hpp"
#include "support/temp_dir.hpp"

namespace matbake {
namespace {

namespace fs = std::filesystem;
constexpr std::size_t kFileBytes = 64 * 1024;

// As OIIO and std::ofstream do: the temporary file is opened by name, here several times over, so
// that an open after the interrupt removed the file is likely.
void write_until_interrupted(const fs::path& folder, int writer) {
  const std::string bytes(kFileBytes, 'x');
  for (int n = 0;; ++n) {
    auto file = AtomicFile::create(folder / ("out-" + std::to_string(writer) + "-" + std::to_string(n) + ".bin"));
    if (!file) return;
    for (int reopen = 0; reopen < 4; ++reopen) std::ofstream(file->temp_path(), std::ios::binary) << bytes;
    (void)file->commit();
  }
}

// In a child process: remove_temporary_files_for_exit() is for a process about to end.
int interrupted_child(const fs::path& folder) {
  for (int writer = 0; writer < 3; ++writer) std::thread(write_until_interrupted, folder, writer).detach();
  // Interrupted once a file is finished (the writers are then at work), however slow the machine.
  const auto finished = [&] {
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.path().filename().string()[0] != '.') return true;
    }
    return false;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!finished() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  remove_temporary_files_for_exit();
  std::this_thread::sleep_for(std::chrono::milliseconds(30));  // the writers go on opening by name
  return 0;
}

TEST(AtomicFile, AnInterruptLeavesFinishedFilesAndNoTemporaryOnes) {
  for (int run = 0; run < 20; ++run) {
    test::TempDir dir;
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) ::_exit(interrupted_child(dir.path()));
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    std::size_t finished = 0;
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      ASSERT_NE(entry.path().filename().string()[0], '.') << "left behind: " << entry.path();
      EXPECT_EQ(fs::file_size(entry.path()), kFileBytes) << entry.path();
      ++finished;
    }
    EXPECT_GT(finished, 0u) << "the writers had not started";
  }
}

TEST(AtomicFile, CommitRenamesAndAnAbandonedFileLeavesNothing) {
  test::TempDir dir;
  {
    auto abandoned = AtomicFile::create(dir / "a.txt");
    ASSERT_TRUE(abandoned);
    std::ofstream(abandoned->temp_path()) << "partial";
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
  ASSERT_TRUE(write_file_atomically(dir / "b.txt", "whole"));
  std::ifstream in(dir / "b.txt");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "whole");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(AtomicFile, APlantedLinkInPlaceOfTheTemporaryFolderIsRefused) {
  test::TempDir dir;
  fs::create_directories(dir / "out");
  fs::create_directory(dir / "elsewhere");
  fs::create_directory_symlink(dir / "elsewhere", dir / "out" / (".matbake-" + std::to_string(getpid())));
  const Status written = write_file_atomically(dir / "out/x.txt", "bytes");
  ASSERT_FALSE(written);
  EXPECT_EQ(written.error().path, (dir / "out/x.txt").string());
  EXPECT_NE(written.error().message.find("is not a folder"), std::string::npos) << written.error().message;
  EXPECT_TRUE(fs::is_empty(dir / "elsewhere"));
  EXPECT_FALSE(fs::exists(dir / "out/x.txt"));
}

}  // namespace
}  // namespace matbake
