// The supervised runner (subprocess.hpp): time limits kill the whole group, output is bounded to
// its tail, the child gets the signals its parent blocks, and nothing it leaves behind outlives it.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "matbake/subprocess.hpp"

namespace matbake::test {
namespace {

using namespace std::chrono_literals;

SubprocessResult shell(const std::string& script, std::chrono::milliseconds limit = 10s) {
  return run_supervised({"/bin/sh", {"-c", script}, limit});
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(Subprocess, ExitCodeAndOutput) {
  const SubprocessResult r = shell("echo one; echo 'ERROR: two' >&2; echo three; exit 3");
  EXPECT_EQ(r.status, 3);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(r.output_tail, "one\nERROR: two\nthree\n");
  EXPECT_EQ(r.error_line(), "ERROR: two");
  EXPECT_EQ(shell("printf 'a\\033[31mb\\n'; exit 1").error_line(), "a\\x1b[31mb");  // escaped
  const SubprocessResult missing = run_supervised({"/nonexistent/program", {}});
  EXPECT_EQ(missing.status, 127);
  EXPECT_EQ(missing.start_error, "cannot be run");
}

// A program that writes where it runs (basisu -unpack) is given its folder; a relative program is
// still found from matbake's own folder; a folder that is not there is a start failure (127).
TEST(Subprocess, RunsInTheFolderItIsGiven) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / ("matbake-wd-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  const std::filesystem::path here = std::filesystem::current_path();
  std::filesystem::current_path("/bin");
  const SubprocessResult r = run_supervised({"sh", {"-c", "pwd"}, 10s, 4096, folder});
  const SubprocessResult missing = run_supervised({"sh", {"-c", "pwd"}, 10s, 4096, folder / "gone"});
  std::filesystem::current_path(here);
  std::filesystem::remove_all(folder);
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.output_tail, folder.string() + "\n");
  EXPECT_EQ(missing.status, 127);
}

// A hung program is killed at its limit, with every process of its group.
TEST(Subprocess, TheTimeLimitKillsTheGroup) {
  const auto start = std::chrono::steady_clock::now();
  const SubprocessResult r = shell("sleep 100 & sleep 100; echo never", 300ms);
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.status, 128 + SIGKILL);
  EXPECT_LT(seconds_since(start), 5.0);
  // A program that ends leaving a process behind (holding the output open) is done when it ends,
  // and what it left is killed.
  const auto second = std::chrono::steady_clock::now();
  const SubprocessResult left = shell("(sleep 100; echo late) & echo done", 20s);
  EXPECT_FALSE(left.timed_out);
  EXPECT_EQ(left.status, 0);
  EXPECT_EQ(left.output_tail, "done\n");
  EXPECT_LT(seconds_since(second), 5.0);
}

// 50 MB of output costs its last 64 KiB, and the error line is the last line.
TEST(Subprocess, OutputIsBoundedToItsTail) {
  const SubprocessResult r = shell("head -c 50000000 /dev/zero | tr '\\0' x; echo; echo 'the last line'; exit 2");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output_tail.size(), 64u * 1024);
  EXPECT_EQ(r.error_line(), "the last line");
  const SubprocessResult long_line = shell("head -c 100000 /dev/zero | tr '\\0' y; exit 1");
  EXPECT_EQ(long_line.error_line(), std::string(297, 'y') + "...");
}

// Signals the parent blocks (matbake blocks SIGINT/SIGTERM/SIGHUP for its interrupt thread) are
// unblocked in the child, with their default actions.
TEST(Subprocess, TheChildGetsTheSignalsItsParentBlocks) {
  sigset_t blocked, old;
  sigemptyset(&blocked);
  sigaddset(&blocked, SIGTERM);
  ASSERT_EQ(pthread_sigmask(SIG_BLOCK, &blocked, &old), 0);
  const SubprocessResult r = shell("kill -TERM $$; sleep 5; echo survived", 20s);
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  EXPECT_EQ(r.status, 128 + SIGTERM);
  EXPECT_EQ(r.output_tail, "");
}

}  // namespace
}  // namespace matbake::test
