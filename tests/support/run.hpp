#pragma once
#include <string>
#include <vector>

namespace matbake::test {

struct RunResult {
  int exit_code = -1;  // 128 + signal when killed by one
  std::string out;
  std::string err;
};

// Runs `program args...` with stdout and stderr captured; `env` entries ("NAME=value") are added
// to (or override) the environment; an entry "NAME=" removes NAME.
RunResult run(const std::string& program, const std::vector<std::string>& args,
              const std::vector<std::string>& env = {});

// The matbake binary built with these tests (or MATBAKE_TEST_EXE, an earlier build's).
std::string matbake_exe();

RunResult matbake(const std::vector<std::string>& args, const std::vector<std::string>& env = {});

}  // namespace matbake::test
