#include "matbake/output_check.hpp"

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
