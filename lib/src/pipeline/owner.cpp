// Who an output folder belongs to (OUT/.matbake/owner.json): two manifests building into one folder
// would each take the other's outputs for stale ones and remove them, then rebuild their own, for
// ever. The first manifest to build there owns it; another is refused unless both say
// `shared_output = true` (then each keeps its state, and cleans, apart, and no two make one file).
// The claim is made under a lock (OUT/.matbake/owner.lock): manifests started at one moment into a
// fresh folder each saw no owner and recorded itself, and one then removed the other's outputs.
#include <fcntl.h>
#include <sys/file.h>

#include <cerrno>
#include <cstring>
#include <set>

#include <nlohmann/json.hpp>

#include "matbake/atomic_file.hpp"
#include "../io/unique_fd.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

constexpr std::size_t kOwnerLimit = 1u << 20;
constexpr std::size_t kClaimLimit = 64u << 20;  // a shared manifest's outputs: 100,000 files ~10 MB

struct Owner {
  std::string manifest;  // relative to the output folder
  bool shared = false;
};

// The recorded owner, when there is a readable one; else a warning and none.
std::optional<Owner> recorded_owner(const fs::path& file, std::vector<std::string>& warnings) {
  const StateText read = read_state_file(file, kOwnerLimit);
  if (read.absent) return std::nullopt;
  const nlohmann::json& j = read.json;
  if (read.problem.empty() && j.is_object() && j.contains("manifest") && j["manifest"].is_string() && j.contains("shared") &&
      j["shared"].is_boolean()) {
    return Owner{j["manifest"].get<std::string>(), j["shared"].get<bool>()};
  }
  warnings.push_back(file.string() + " " + (read.problem.empty() ? "is not one matbake wrote" : read.problem) +
                     "; ignored (this manifest records itself as the folder's owner)");
  return std::nullopt;
}

// The lock every claim of the folder holds (a link planted as the lock is refused, not followed):
// its descriptor.
Result<int> lock_owner(const fs::path& state_folder) {
  std::error_code ec;
  fs::create_directories(state_folder, ec);
  const fs::path file = state_folder / "owner.lock";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  if (fd < 0) return Error{file.string(), std::string("cannot be locked: ") + (errno == ELOOP ? "it is a link" : std::strerror(errno))};
  while (::flock(fd, LOCK_EX) != 0) {
    if (errno != EINTR) {
      ::close(fd);
      return Error{file.string(), std::string("cannot be locked: ") + std::strerror(errno)};
    }
  }
  return fd;
}

// A shared manifest's claim (its state folder's claim.json): the manifest and the files it makes,
// relative to the output folder. Another shared manifest making one of them is refused: the two
// would overwrite each other's file and rebuild it on every run.
nlohmann::json claim_of(const Manifest& manifest, const Plan& plan) {
  nlohmann::json outputs = nlohmann::json::array();
  for (const Job& job : plan.jobs) {
    for (const fs::path& p : job.outputs.all()) outputs.push_back(stamped_path(p, manifest.output));
  }
  return {{"manifest", plan.owner}, {"outputs", outputs}};
}

Status check_shared_claims(const Manifest& manifest, const Plan& plan, const nlohmann::json& claim) {
  const std::set<std::string> mine(claim["outputs"].begin(), claim["outputs"].end());
  std::error_code ec;
  for (const fs::directory_entry& other : fs::directory_iterator(manifest.output / ".matbake" / "shared", ec)) {
    if (other.path() == plan.state_folder || !fs::is_directory(other.symlink_status(ec))) continue;
    const StateText read = read_state_file(other.path() / "claim.json", kClaimLimit);
    const nlohmann::json& j = read.json;
    if (!read.problem.empty() || !j.is_object() || !j.contains("manifest") || !j["manifest"].is_string() ||
        !j.contains("outputs") || !j["outputs"].is_array() || j["manifest"] == plan.owner ||
        !fs::is_regular_file(resolved_path(j["manifest"].get<std::string>(), manifest.output), ec)) {
      continue;  // absent, not one matbake wrote, or of a manifest that is gone: nothing claimed
    }
    for (const nlohmann::json& file : j["outputs"]) {
      if (!file.is_string() || !mine.contains(file.get<std::string>())) continue;
      return Error{manifest.file.string(), "makes " + (manifest.output / file.get<std::string>()).string() + ", which " +
                                               resolved_path(j["manifest"].get<std::string>(), manifest.output).string() +
                                               " also makes in the shared output folder; each would overwrite the other's: "
                                               "rename one of them"};
    }
  }
  return success();
}

Status check_owner(const Manifest& manifest, const Plan& plan, const std::optional<Owner>& owner, const fs::path& file) {
  if (owner && owner->manifest != plan.owner && !(owner->shared && manifest.shared_output)) {
    return Error{manifest.file.string(), "its output folder " + manifest.output.string() + " belongs to " +
                                             resolved_path(owner->manifest, manifest.output).string() + " (" + file.string() +
                                             "); two manifests building into one folder remove each other's outputs: give this "
                                             "one its own " + mention("output") + ", or set " + mention("shared_output", "true") + " in both"};
  }
  return success();
}

}  // namespace

Status claim_output_folder(const Manifest& manifest, const Plan& plan, bool record, std::vector<std::string>& warnings) {
  const fs::path state = manifest.output / ".matbake", file = state / "owner.json";
  if (!record) return check_owner(manifest, plan, recorded_owner(file, warnings), file);
  const auto lock = lock_owner(state);
  if (!lock) return lock.error();
  const UniqueFd held(*lock);
  const std::optional<Owner> owner = recorded_owner(file, warnings);
  if (Status s = check_owner(manifest, plan, owner, file); !s) return s;
  if (manifest.shared_output) {
    const nlohmann::json claim = claim_of(manifest, plan);
    if (Status s = check_shared_claims(manifest, plan, claim); !s) return s;
    std::error_code ec;
    fs::create_directories(plan.state_folder, ec);
    if (Status s = write_file_atomically(plan.state_folder / "claim.json", claim.dump() + "\n"); !s) return s;
  }
  if (owner && (owner->manifest != plan.owner || owner->shared == manifest.shared_output)) return success();  // shared: the first stays recorded
  const nlohmann::json j = {{"manifest", plan.owner}, {"shared", manifest.shared_output}};
  return write_file_atomically(file, j.dump(1) + "\n");
}

}  // namespace matbake::pipeline
