#include "made_log.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cerrno>
#include <set>

#include "matbake/atomic_file.hpp"
#include "matbake/read_file.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

constexpr int kLogForm = 1;

fs::path log_path(const StampRoots& roots) { return roots.state_folder / "made.json"; }

MadeLog::Files files_in(const nlohmann::json& j) {
  MadeLog::Files files;
  if (!j.is_object()) return files;
  for (const auto& [path, hash] : j.items()) {
    if (hash.is_string()) files[path] = hash.get<std::string>();
  }
  return files;
}

}  // namespace

MadeLogLock::MadeLogLock(const StampRoots& roots) {
  fd_ = ::open((roots.state_folder / "made.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  while (fd_ >= 0 && ::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
  }
}

MadeLogLock::~MadeLogLock() {
  if (fd_ >= 0) ::close(fd_);
}

MadeLog read_made_log(const StampRoots& roots) {
  MadeLog log;
  std::string text;
  if (!read_whole_file(log_path(roots), text)) return log;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object() || j.value("form", 0) != kLogForm) return log;
  if (j.contains("jobs") && j["jobs"].is_object()) {
    for (const auto& [name, files] : j["jobs"].items()) log.jobs[name] = files_in(files);
  }
  if (j.contains("stale")) log.stale = files_in(j["stale"]);
  return log;
}

Status write_made_log(const MadeLog& log, const StampRoots& roots) {
  const nlohmann::json j = {{"form", kLogForm}, {"jobs", log.jobs}, {"stale", log.stale}};
  return write_file_atomically(log_path(roots), j.dump(1) + "\n");
}

std::vector<std::string> record_run(MadeLog& log, const Plan& plan, const Report& report, const StampRoots& roots) {
  for (const JobReport& r : report.jobs) {
    // A built job's entry is what it wrote; an up-to-date one's what its stamp says (a run killed
    // before it wrote the log leaves stamps the log does not have yet).
    if (r.outcome != Outcome::built && r.outcome != Outcome::up_to_date) continue;
    MadeLog::Files now;
    for (const auto& [path, hash] : r.written) now[stamped_path(path, roots.outputs)] = hash;
    for (const auto& [path, hash] : log.jobs[r.job->name]) {
      if (!now.count(path)) log.stale[path] = hash;
    }
    log.jobs[r.job->name] = std::move(now);
  }
  std::set<std::string> planned, current;
  for (const Job& job : plan.jobs) {
    planned.insert(job.name);
    for (const fs::path& p : job.outputs.all()) current.insert(stamped_path(p, roots.outputs));
  }
  std::vector<std::string> gone;
  for (auto it = log.jobs.begin(); it != log.jobs.end();) {
    if (planned.count(it->first)) {
      for (const auto& [path, hash] : it->second) current.insert(path);
      ++it;
      continue;
    }
    gone.push_back(it->first);
    log.stale.insert(it->second.begin(), it->second.end());
    it = log.jobs.erase(it);
  }
  for (const std::string& path : current) log.stale.erase(path);
  return gone;
}

StaleOutputs clean_stale(MadeLog& log, const StampRoots& roots, bool remove) {
  StaleOutputs result;
  for (auto it = log.stale.begin(); it != log.stale.end();) {
    const fs::path file = resolved_path(it->first, roots.outputs);
    std::error_code ec;
    const std::optional<FileIdentity> now = fs::is_regular_file(file, ec) ? identify(file) : std::nullopt;
    if (!now || now->hash != it->second) {
      if (now) result.changed.push_back(file);
      it = log.stale.erase(it);
    } else if (remove && fs::remove(file, ec)) {
      result.removed.push_back(file);
      it = log.stale.erase(it);
    } else {
      result.kept.push_back(file);
      ++it;
    }
  }
  return result;
}

}  // namespace matbake::pipeline
