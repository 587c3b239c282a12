// Outputs through a temporary file and a rename; an interrupt leaves finished files and no temporary ones.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
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

// A run killed with SIGKILL leaves its temporary folder: the next run in that folder removes it
// when its owner is provably gone (this host and a PID that runs nothing, or another host's after
// a day), and never a live process's (it holds the folder's lock), whatever its PID says.
TEST(AtomicFile, LeftoverTemporaryFoldersGoWhenTheirOwnerProvablyHas) {
  test::TempDir dir;
  char host_text[256] = {};
  ASSERT_EQ(gethostname(host_text, sizeof host_text - 1), 0);
  std::string host = host_text;  // as the folder names it: '-' is its separator
  for (char& c : host) c = std::isalnum(static_cast<unsigned char>(c)) || c == '.' ? c : '_';
  const auto leftover = [&](const std::string& name) {
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "scratch.png") << "partial";
    return dir / name;
  };
  pid_t dead = 1 << 22;  // above Linux's pid_max
  const fs::path gone = leftover(".matbake-tmp-" + host + "-" + std::to_string(dead) + "-00");
  const fs::path live = leftover(".matbake-tmp-" + host + "-" + std::to_string(dead) + "-11");  // same PID, other namespace
  const fs::path other_fresh = leftover(".matbake-tmp-elsewhere-1-22");
  const fs::path other_old = leftover(".matbake-tmp-elsewhere-1-33");
  const fs::path not_ours = leftover(".matbake-tmpfoo");
  const int held = ::open(live.c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_EQ(::flock(held, LOCK_EX), 0);
  const timespec two_days_ago[2] = {{time(nullptr) - 2 * 86400, 0}, {time(nullptr) - 2 * 86400, 0}};
  ASSERT_EQ(::utimensat(AT_FDCWD, other_old.c_str(), two_days_ago, 0), 0);
  ASSERT_TRUE(write_file_atomically(dir / "x.txt", "bytes"));
  EXPECT_FALSE(fs::exists(gone));
  EXPECT_FALSE(fs::exists(other_old));
  EXPECT_TRUE(fs::exists(live / "scratch.png"));
  EXPECT_TRUE(fs::exists(other_fresh / "scratch.png"));
  EXPECT_TRUE(fs::exists(not_ours / "scratch.png"));
  ::close(held);
  // This run's own folder: host, PID and a random token; gone once its last file is.
  auto file = AtomicFile::create(dir / "y.txt");
  ASSERT_TRUE(file);
  const std::string own = file->temp_path().parent_path().filename().string();
  EXPECT_EQ(own.rfind(".matbake-tmp-" + host + "-" + std::to_string(getpid()) + "-", 0), 0u) << own;
  EXPECT_EQ(own.size(), (".matbake-tmp-" + host + "-" + std::to_string(getpid()) + "-").size() + 16);
}

}  // namespace
}  // namespace matbake
