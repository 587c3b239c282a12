#pragma once
// Real paths (links resolved, as fs::weakly_canonical gives them) of many files in few folders: each
// folder is resolved and listed once (which of its entries are links), so a file costs no system
// call (not a readlink per component, nor an lstat). A build's plan checks 20,000 outputs so
// (docs/build.md, "A no-op run at scale"). Not for use from two threads at once.
#include <filesystem>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace matbake {

class RealPaths {
 public:
  // The real path of `path` (made absolute; one with `.` or `..` parts is resolved by
  // fs::weakly_canonical, links before `..` first, as the system does).
  const std::filesystem::path& of(const std::filesystem::path& path);
  // Whether `path`'s real path is `folder`'s or below it.
  bool inside(const std::filesystem::path& folder, const std::filesystem::path& path);

 private:
  const std::unordered_set<std::string>& links_in(const std::filesystem::path& folder);

  std::unordered_map<std::string, std::filesystem::path> known_;  // by the native string: fs::path compares by component, slowly
  std::unordered_map<std::string, std::unordered_set<std::string>> links_;  // folder → names of its links
};

}  // namespace matbake
