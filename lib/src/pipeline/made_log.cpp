#include "made_log.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cerrno>
#include <set>

#include "matbake/atomic_file.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

constexpr int kLogForm = 1;

fs::path log_path(const StampRoots& roots) { return roots.state_folder / "made.json"; }

bool is_hash(const nlohmann::json& h) {
  if (!h.is_string()) return false;
  const std::string& text = h.get_ref<const std::string&>();
  return text.size() == 16 && text.find_first_not_of("0123456789abcdef") == std::string::npos;
}

// Files by path, each with a hash; empty (and `problem` said) when `j` is not that.
MadeLog::Files files_in(const nlohmann::json& j, std::string& problem) {
  MadeLog::Files files;
  if (!j.is_object()) {
    problem = "a list of files that is not an object";
    return files;
  }
  for (const auto& [path, hash] : j.items()) {
    if (!is_hash(hash)) {
      problem = "a file without its hash";
      return {};
    }
    files[path] = hash.get<std::string>();
  }
  return files;
}

// The log in `j`, or why it is not one matbake wrote.
std::string parse_log(const nlohmann::json& j, MadeLog& log) {
  if (!j.is_object() || !j.contains("form") || j["form"] != kLogForm) return "is not a log of this matbake (form " + std::to_string(kLogForm) + ")";
  if (!j.contains("jobs") || !j["jobs"].is_object() || !j.contains("stale")) return "has no jobs or stale files";
  std::string problem;
  for (const auto& [name, files] : j["jobs"].items()) {
    log.jobs[name] = files_in(files, problem);
    if (!problem.empty()) return "has " + problem;
  }
  log.stale = files_in(j["stale"], problem);
  return problem.empty() ? problem : "has " + problem;
}

}  // namespace

MadeLogLock::MadeLogLock(const StampRoots& roots) {
  // O_NOFOLLOW: a link planted as the lock would otherwise make its target, wherever it points.
  const fs::path file = roots.state_folder / "made.lock";
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  if (fd_ < 0 && errno == ELOOP) problem_ = file.string() + " is a link (matbake's state files never are); the log of files made is not updated";
  while (fd_ >= 0 && ::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
  }
}

MadeLogLock::~MadeLogLock() {
  if (fd_ >= 0) ::close(fd_);
}

MadeLog read_made_log(const StampRoots& roots, std::string& problem) {
  const StateText read = read_state_file(log_path(roots), kMadeLogLimit);
  problem = read.problem;
  MadeLog log;
  if (read.absent || !problem.empty()) return log;
  problem = parse_log(read.json, log);
  if (!problem.empty()) log = {};
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

StaleOutputs clean_stale(MadeLog& log, const OutputGate& gate, const StampRoots& roots, bool remove) {
  StaleOutputs result;
  for (auto it = log.stale.begin(); it != log.stale.end();) {
    const RemoveResult r = gate.remove_made(it->first, it->second, !remove);
    const fs::path file = resolved_path(it->first, roots.outputs);
    if (r.outcome == RemoveOutcome::removed && !remove) {
      result.kept.push_back(file);
      ++it;
      continue;
    }
    if (r.outcome == RemoveOutcome::removed) result.removed.push_back(file);
    if (r.outcome == RemoveOutcome::changed) result.changed.push_back(file);
    if (r.outcome == RemoveOutcome::refused) result.refused.push_back("'" + it->first + "': " + r.why);
    it = log.stale.erase(it);
  }
  return result;
}

}  // namespace matbake::pipeline
