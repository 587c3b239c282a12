#pragma once
#include <string>
#include <vector>

namespace matbake::test {

struct RunResult {
  int exit_code = -1;  // 128 + signal when killed by one
  std::string out;
  std::string err;
  double peak_mb = 0;  // run_measured: the most memory its processes held at once (MiB)
};

// Runs `program args...` with stdout and stderr captured; `env` entries ("NAME=value") are added
// to (or override) the environment; an entry "NAME=" removes NAME.
// Where `tool` is on PATH; empty when it is not.
std::string tool_path(const std::string& tool);

RunResult run(const std::string& program, const std::vector<std::string>& args,
              const std::vector<std::string>& env = {});

// run, in a process group of its own (killed as one), its memory and its descendants' summed every
// 5 ms as proportional set sizes (tree_memory_bytes in run.cpp), as a cluster's cgroup
// counts a job and the encoders it starts: the peak of the sums, or the largest single process's
// own peak (the kernel's, between samples) when that is higher.
RunResult run_measured(const std::string& program, const std::vector<std::string>& args,
                       const std::vector<std::string>& env = {});

// The matbake binary built with these tests (or MATBAKE_TEST_EXE, an earlier build's).
std::string matbake_exe();

RunResult matbake(const std::vector<std::string>& args, const std::vector<std::string>& env = {});
// The environment matbake() runs it with: `env` and the installed KTX2 encoder.
std::vector<std::string> matbake_environment(const std::vector<std::string>& env = {});

}  // namespace matbake::test
