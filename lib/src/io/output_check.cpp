#include "matbake/output_check.hpp"

#include <algorithm>

namespace matbake {
namespace fs = std::filesystem;

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  const fs::path real_a = fs::weakly_canonical(fs::absolute(a, ec), ec);
  const fs::path real_b = fs::weakly_canonical(fs::absolute(b, ec), ec);
  if (!real_a.empty() && real_a == real_b) return true;
  ec.clear();
  const bool equivalent = fs::equivalent(a, b, ec);  // hard links; false when either is missing
  return !ec && equivalent;
}

bool is_really_inside(const fs::path& folder, const fs::path& path) {
  std::error_code ec;
  const fs::path real_folder = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  if (ec) return false;
  const fs::path real = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) return false;
  const auto [f, p] = std::mismatch(real_folder.begin(), real_folder.end(), real.begin(), real.end());
  return f == real_folder.end() || (std::next(f) == real_folder.end() && f->empty());
}

Status check_outputs(std::span<const NamedOutput> outputs, std::span<const fs::path> inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const NamedOutput& out = outputs[i];
    if (out.path.empty()) continue;
    for (const fs::path& in : inputs) {
      if (!in.empty() && same_file(out.path, in)) {
        return Error{out.path.string(), "is an input; matbake never overwrites its inputs", true};
      }
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && same_file(out.path, outputs[j].path)) {
        return Error{out.path.string(), "is written twice (" + outputs[j].role + " and " + out.role + ")", true};
      }
    }
  }
  return success();
}

}  // namespace matbake
