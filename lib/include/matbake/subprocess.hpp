#pragma once
// The one way matbake runs another program (basisu now): supervised, so that it can neither hang a
// build, outlive it, nor flood it (docs/reliability.md).
//
// The child runs in its own process group with the signals matbake blocks unblocked and their
// default actions restored, stdin from /dev/null. The group's leader is a small supervisor (a fork
// of matbake) that starts the program and kills the whole group, itself included, when matbake's
// end of a pipe closes: matbake exited or was killed with SIGKILL, so no descendant of the program
// (a wrapper's basisu) outlives it, unless it left the group itself (setsid). Its stdout and stderr
// go to a pipe of which only the last `output_limit` bytes are kept. At `time_limit` its group is
// killed.
// An interrupt of matbake (SIGINT, SIGTERM, SIGHUP) kills every running group
// (kill_subprocesses_for_exit, from the interrupt thread).
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace matbake {

struct SubprocessRequest {
  std::filesystem::path program;
  std::vector<std::string> args;
  std::chrono::milliseconds time_limit{std::chrono::seconds(60)};
  std::size_t output_limit = 64 * 1024;  // the last bytes of stdout and stderr kept
  std::filesystem::path working_directory;  // where it runs (for a program that writes its files
                                            // there); empty: matbake's own
};

struct SubprocessResult {
  int status = -1;          // the exit code; 128 + signal when killed; -1 when it could not start
  bool timed_out = false;   // its group was killed at the time limit
  std::string output_tail;  // the last output_limit bytes it wrote (stdout and stderr)
  std::string start_error;  // why it could not start (status -1)

  // The line worth showing: the first "ERROR"/"Error" line of the kept output, else its last line;
  // control characters escaped, at most 300 characters.
  std::string error_line() const;
};

SubprocessResult run_supervised(const SubprocessRequest& request);

// Kills the process group of every program running now and keeps new ones from starting: for the
// interrupt handler's thread, before it exits.
void kill_subprocesses_for_exit();

}  // namespace matbake
