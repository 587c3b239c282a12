#pragma once
// The CLI's error contract, checked the same way by every CLI test.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "support/run.hpp"

namespace matbake::test {

// Exactly one line on stderr, in the documented form `matbake: error: <path>: <problem>…`.
inline void expect_one_error_line(const RunResult& r, const std::string& path, const std::string& problem) {
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const std::string expected = "matbake: error: " + (path.empty() ? "" : path + ": ") + problem;
  EXPECT_EQ(r.err.rfind(expected, 0), 0u) << "stderr: " << r.err << "expected: " << expected;
}

}  // namespace matbake::test
