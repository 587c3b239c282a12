#include "real_paths.hpp"

#include <algorithm>

namespace matbake {
namespace fs = std::filesystem;
namespace {

bool is_normal_absolute(const fs::path& p) {
  if (!p.is_absolute()) return false;
  return std::none_of(p.begin(), p.end(), [](const fs::path& part) { return part == "." || part == ".."; });
}

}  // namespace

const fs::path& RealPaths::of(const fs::path& path) {
  if (const auto found = known_.find(path.native()); found != known_.end()) return found->second;
  std::error_code ec;
  fs::path real = fs::absolute(path, ec);
  if (!is_normal_absolute(real)) {
    fs::path resolved = fs::weakly_canonical(real, ec);
    real = ec ? real.lexically_normal() : std::move(resolved);
  } else if (real.has_relative_path()) {
    const fs::path& folder = of(real.parent_path());
    const fs::path name = real.filename();
    real = name.empty() ? folder : folder / name;  // "out/" is "out"
    if (!name.empty() && links_in(folder).count(name.native())) {
      fs::path resolved = fs::weakly_canonical(real, ec);
      if (!ec) real = std::move(resolved);
    }
  }
  return known_.emplace(path.native(), std::move(real)).first->second;
}

bool RealPaths::inside(const fs::path& folder, const fs::path& path) {
  const fs::path& f = of(folder);  // the table's nodes stay where they are as it grows
  const fs::path& p = of(path);
  const auto [end, rest] = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return end == f.end();
}

const std::unordered_set<std::string>& RealPaths::links_in(const fs::path& folder) {
  auto [found, added] = links_.try_emplace(folder.native());
  if (added) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      if (entry.is_symlink(ec)) found->second.insert(entry.path().filename().native());
    }
  }
  return found->second;
}

}  // namespace matbake
