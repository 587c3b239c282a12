#pragma once
// The Basis Universal encoder the KTX2 tests run: MATBAKE_BASISU when set, else the one
// scripts/install-basisu.sh installs. Tests that need it skip, saying why, when neither runs.
#include <gtest/gtest.h>

#include <string>

namespace matbake::test {

// The encoder's path, or "" with the reason in `why_not`.
std::string basisu_for_tests(std::string& why_not);

}  // namespace matbake::test

#define MATBAKE_BASISU_OR_SKIP(path)                                         \
  std::string path##_why_not;                                                \
  const std::string path = ::matbake::test::basisu_for_tests(path##_why_not); \
  if (path.empty()) GTEST_SKIP() << path##_why_not
