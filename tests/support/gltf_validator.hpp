#pragma once
// The Khronos glTF-Validator (scripts/gltf-validator, installed by scripts/install-gltf-validator.sh)
// run on a written file. Tests skip, saying why, only where it is not installed.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace matbake::test {

struct ValidatorReport {
  int errors = 0, warnings = 0, infos = 0;
  std::vector<std::string> error_and_warning_codes;  // "CODE pointer", in the validator's order
  std::string summary;                               // for failure messages
};

// Empty when the validator is not installed; `why_not` then says so.
std::optional<ValidatorReport> validate_gltf(const std::filesystem::path& file, std::string& why_not);

}  // namespace matbake::test

// In a test: the report of `file`, or skip the test when the validator is missing.
#define MATBAKE_VALIDATE_OR_SKIP(report, file)                       \
  std::string report##_why_not;                                      \
  const auto report = ::matbake::test::validate_gltf(file, report##_why_not); \
  if (!report) GTEST_SKIP() << report##_why_not
