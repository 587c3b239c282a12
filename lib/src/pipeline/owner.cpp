// Who an output folder belongs to (OUT/.matbake/owner.json): two manifests building into one folder
// would each take the other's outputs for stale ones and remove them, then rebuild their own, for
// ever. The first manifest to build there owns it; another is refused unless both say
// `shared_output = true` (then each keeps its state, and cleans, apart).
#include <nlohmann/json.hpp>

#include "matbake/atomic_file.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

constexpr std::size_t kOwnerLimit = 1u << 20;

struct Owner {
  std::string manifest;  // relative to the output folder
  bool shared = false;
};

// The recorded owner, when there is a readable one; else a warning and none.
std::optional<Owner> recorded_owner(const fs::path& file, std::vector<std::string>& warnings) {
  const StateText read = read_state_file(file, kOwnerLimit);
  if (read.absent) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(read.text, nullptr, false);
  if (read.problem.empty() && j.is_object() && j.contains("manifest") && j["manifest"].is_string() && j.contains("shared") &&
      j["shared"].is_boolean()) {
    return Owner{j["manifest"].get<std::string>(), j["shared"].get<bool>()};
  }
  warnings.push_back(file.string() + " " + (read.problem.empty() ? "is not one matbake wrote" : read.problem) +
                     "; ignored (this manifest records itself as the folder's owner)");
  return std::nullopt;
}

}  // namespace

Status claim_output_folder(const Manifest& manifest, const Plan& plan, bool record, std::vector<std::string>& warnings) {
  const fs::path file = manifest.output / ".matbake" / "owner.json";
  const std::optional<Owner> owner = recorded_owner(file, warnings);
  if (owner && owner->manifest != plan.owner && !(owner->shared && manifest.shared_output)) {
    return Error{manifest.file.string(), "its output folder " + manifest.output.string() + " belongs to " +
                                             resolved_path(owner->manifest, manifest.output).string() + " (" + file.string() +
                                             "); two manifests building into one folder remove each other's outputs: give this "
                                             "one its own " + mention("output") + ", or set " + mention("shared_output", "true") + " in both"};
  }
  if (!record || (owner && owner->manifest == plan.owner && owner->shared == manifest.shared_output)) return success();
  if (owner && owner->manifest != plan.owner) return success();  // shared: the first stays recorded
  std::error_code ec;
  fs::create_directories(file.parent_path(), ec);
  const nlohmann::json j = {{"manifest", plan.owner}, {"shared", manifest.shared_output}};
  return write_file_atomically(file, j.dump(1) + "\n");
}

}  // namespace matbake::pipeline
