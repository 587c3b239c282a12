#include "state.hpp"

#include <fcntl.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <set>

#include "matbake/atomic_file.hpp"
#include "matbake/output_gate.hpp"
#include "../io/bounded_json.hpp"
#include "matbake/version.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

// The form of a stamp: raised when the same manifest is recorded differently (2: options by their
// parameter descriptions' names, sorted; 3: paths relative to the manifest's and output folders,
// outputs hashed; 4: each job's options only those it reads), so that an older stamp says why it
// rebuilds once rather than "its options changed".
constexpr int kStampForm = 4;

fs::path stamp_path(const std::string& job_name, const StampRoots& roots) {
  return roots.state_folder / (job_file_stem(job_name) + ".json");
}

nlohmann::json stamped_file_json(const FileIdentity& f, const std::string& path) {
  return {{"path", path}, {"size", f.size}, {"mtime", f.mtime}, {"hash", f.hash}};
}

FileIdentity identity_in(const nlohmann::json& f) {
  return {f["size"].get<std::uintmax_t>(), f["mtime"].get<std::int64_t>(), f["hash"].get<std::string>()};
}

// Why a file entry of a stamp is not one matbake wrote, or empty.
std::string file_entry_problem(const nlohmann::json& f, bool output) {
  if (!f.is_object() || !f.contains("path") || !f["path"].is_string()) return "a file without a path";
  if (!f.contains("size") || !f["size"].is_number_unsigned() || !f.contains("mtime") || !f["mtime"].is_number_integer() ||
      !f.contains("hash") || !f["hash"].is_string()) {
    return "a file without its size, time or hash";
  }
  const std::string path = f["path"].get<std::string>();
  if (path.empty() || path.find('\0') != std::string::npos) return "an empty path";
  if (output) {
    if (const std::string problem = recorded_path_problem(path); !problem.empty()) return "an output path with " + problem;
  }
  return {};
}

// Why a stamp's JSON is not one matbake wrote (every field of the right type), or empty.
std::string stamp_problem(const nlohmann::json& stamp) {
  if (!stamp.is_object()) return "not a JSON object";
  if (!stamp.contains("form")) return {};  // the first form had none: said as older
  if (!stamp["form"].is_number_integer()) return "a form that is not a number";
  if (stamp["form"].get<std::int64_t>() != kStampForm) return {};  // an older form: said as such
  for (const char* key : {"matbake", "options", "job"}) {
    if (!stamp.contains(key) || !stamp[key].is_string()) return std::string("no '") + key + "' text";
  }
  for (const char* key : {"inputs", "outputs"}) {
    if (!stamp.contains(key) || !stamp[key].is_array()) return std::string("no '") + key + "' list";
    for (const nlohmann::json& f : stamp[key]) {
      if (std::string why = file_entry_problem(f, key[0] == 'o'); !why.empty()) return why;
    }
  }
  return {};
}

// Each value that differs between a stamp's options and the job's, by its dotted path (objects
// walked, anything else compared whole): {"parameter", "old", "new"}, null where one has none.
void option_changes(const nlohmann::json& was, const nlohmann::json& now, const std::string& path, nlohmann::json& out) {
  if (was == now) return;
  if (!was.is_object() || !now.is_object()) {
    out.push_back({{"parameter", path}, {"old", was}, {"new", now}});
    return;
  }
  std::set<std::string> keys;
  for (const auto& [key, value] : was.items()) keys.insert(key);
  for (const auto& [key, value] : now.items()) keys.insert(key);
  for (const std::string& key : keys) {
    const nlohmann::json none;
    option_changes(was.contains(key) ? was[key] : none, now.contains(key) ? now[key] : none,
                   path.empty() ? key : path + "." + key, out);
  }
}

std::string shown(const nlohmann::json& value) { return value.is_null() ? "(unset)" : value.dump(); }

// "its options changed: validate.worst 5 → 6 (and 2 more)"; a KTX2 scene's encoder gone is said as
// such (the identity holds basisu's version, or "none: " and why it was not found).
std::string options_reason(const nlohmann::json& changes) {
  for (const nlohmann::json& c : changes) {
    if (c["parameter"] == "encoder" && c["new"].is_string() && c["new"].get<std::string>().rfind("none: ", 0) == 0) {
      return "basisu is missing: " + c["new"].get<std::string>().substr(6);
    }
  }
  if (changes.empty()) return "its options changed";
  const nlohmann::json& first = changes[0];
  std::string why = "its options changed: " + first["parameter"].get<std::string>() + " " + shown(first["old"]) +
                    " → " + shown(first["new"]);
  if (changes.size() > 1) why += " (and " + std::to_string(changes.size() - 1) + " more)";
  return why;
}

// Empty when the recorded file is as it was (its time refreshed in `f` when only that moved),
// else what is wrong with it.
std::string check_recorded(nlohmann::json& f, const fs::path& p, const char* missing, const char* changed, bool& touched) {
  const FileIdentity recorded = identity_in(f);
  const std::optional<FileStat> now_stat = stat_file(p);  // one system call: the common case
  if (!now_stat) return missing + p.string();
  if (now_stat->size == recorded.size && now_stat->mtime == recorded.mtime) return {};
  const std::optional<FileIdentity> now = identify(p);
  if (!now || now->hash != recorded.hash) return changed + p.string();
  f["mtime"] = now->mtime;
  touched = true;
  return {};
}

}  // namespace

nlohmann::json options_json(const std::string& text) {
  std::string problem;
  nlohmann::json options = parse_bounded_json<nlohmann::json>(text, kStampLimit, problem);
  return problem.empty() ? options : nlohmann::json();
}

std::string job_file_stem(const std::string& job_name) {
  std::string stem = job_name;
  if (const std::size_t colon = stem.find(':'); colon != std::string::npos) stem[colon] = '-';
  return stem;
}

std::string stamped_path(const fs::path& p, const fs::path& root) {
  const fs::path relative = p.lexically_relative(root);
  return relative.empty() ? p.generic_string() : relative.generic_string();
}

fs::path resolved_path(const std::string& stamped, const fs::path& root) {
  const fs::path p(stamped);
  return p.is_absolute() ? p : (root / p).lexically_normal();
}

Result<std::vector<StampedFile>> identify_all(const std::vector<fs::path>& files) {
  std::vector<StampedFile> identified;
  for (const fs::path& p : files) {
    const std::optional<FileIdentity> identity = identify(p);
    if (!identity) return Error{p.string(), "cannot be read back after it was written"};
    identified.push_back({p, *identity});
  }
  return identified;
}

std::string content_hash(std::span<const unsigned char> bytes) { return hash_bytes(bytes); }

StateText read_state_file(const fs::path& file, std::size_t limit) {
  StateText out;
  const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    out.absent = errno == ENOENT;
    if (!out.absent) out.problem = errno == ELOOP ? "is a link (matbake's state files never are)" : std::strerror(errno);
    return out;
  }
  struct stat s;
  if (::fstat(fd, &s) != 0 || !S_ISREG(s.st_mode)) {
    out.problem = "is not a regular file";
  } else if (std::size_t(s.st_size) > limit) {
    out.problem = "is " + std::to_string(s.st_size) + " bytes, over the " + std::to_string(limit >> 20) + " MiB a state file may hold";
  } else {
    out.text.resize(std::size_t(s.st_size));
    std::size_t done = 0;
    while (done < out.text.size()) {
      const ssize_t n = ::read(fd, out.text.data() + done, out.text.size() - done);
      if (n == 0) break;
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        out.problem = std::strerror(errno);
        break;
      }
      done += std::size_t(n);
    }
    out.text.resize(done);
    if (out.problem.empty()) out.json = parse_bounded_json<nlohmann::json>(out.text, limit, out.problem);
  }
  ::close(fd);
  return out;
}

std::optional<FileStat> stat_file(const fs::path& file) {
  struct stat s;
  if (::stat(file.c_str(), &s) != 0) return std::nullopt;
  return FileStat{std::uintmax_t(s.st_size), std::int64_t(s.st_mtim.tv_sec) * 1000000000 + s.st_mtim.tv_nsec};
}

std::optional<std::int64_t> modification_time(const fs::path& file) {
  const std::optional<FileStat> s = stat_file(file);
  if (!s) return std::nullopt;
  return s->mtime;
}

std::optional<FileIdentity> identify(const fs::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  struct stat s;
  std::optional<FileIdentity> identity;
  if (::fstat(fd, &s) == 0 && S_ISREG(s.st_mode)) {
    // The time first, then the bytes (streamed: constant memory whatever the size).
    const std::int64_t mtime = std::int64_t(s.st_mtim.tv_sec) * 1000000000 + s.st_mtim.tv_nsec;
    std::string hash = hash_file_descriptor(fd);
    if (!hash.empty()) identity = FileIdentity{std::uintmax_t(s.st_size), mtime, std::move(hash)};
  }
  ::close(fd);
  return identity;
}

bool changed_since(const fs::path& file, const FileIdentity& read) {
  const std::optional<FileStat> s = stat_file(file);
  if (s && s->size == read.size && s->mtime == read.mtime) return false;
  const std::optional<FileIdentity> now = identify(file);
  return !now || now->hash != read.hash;
}

std::string out_of_date_reason(const Job& job, const StampRoots& roots, bool refresh, std::map<fs::path, std::string>* recorded_outputs,
                               nlohmann::json* changed) {
  const fs::path file = stamp_path(job.name, roots);
  StateText read = read_state_file(file, kStampLimit);
  if (read.absent) return "no earlier build";
  nlohmann::json stamp = std::move(read.json);
  std::string problem = read.problem;
  if (problem.empty()) problem = stamp_problem(stamp);
  if (!problem.empty()) return std::string(kBadStamp) + file.string() + " " + (read.problem.empty() ? "is not one matbake wrote: " : "") + problem;
  if (stamp.value("form", 1) != kStampForm) return "its stamp is from an older matbake (recorded anew)";
  if (stamp["matbake"] != version) return "matbake's version changed";
  if (stamp["options"] != job.options) {
    nlohmann::json changes = nlohmann::json::array();
    option_changes(options_json(stamp["options"].get<std::string>()), options_json(job.options), "", changes);
    if (changed) *changed = changes;
    return options_reason(changes);
  }
  std::vector<fs::path> recorded;
  for (const nlohmann::json& f : stamp["inputs"]) recorded.push_back(resolved_path(f["path"].get<std::string>(), roots.inputs));
  for (const fs::path& p : job.inputs) {
    if (std::find(recorded.begin(), recorded.end(), p) == recorded.end()) return "new input: " + p.string();
  }
  bool touched = false;
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    std::string why = check_recorded(stamp["inputs"][i], recorded[i], "input missing: ", "input changed: ", touched);
    if (!why.empty()) return why;
  }
  std::vector<fs::path> made;
  for (nlohmann::json& f : stamp["outputs"]) {
    const fs::path p = resolved_path(f["path"].get<std::string>(), roots.outputs);
    std::string why = check_recorded(f, p, "output missing: ", "output changed since it was built: ", touched);
    if (!why.empty()) return why;
    made.push_back(p);
  }
  // An output its last run did not write (a matbake that writes more, such as a material's ball).
  for (const fs::path& p : job.outputs.all()) {
    if (std::find(made.begin(), made.end(), p) == made.end()) return "new output: " + p.string();
  }
  // Best effort: a stamp that cannot be written again only costs the next run some hashing.
  if (touched && refresh) (void)write_file_atomically(stamp_path(job.name, roots), stamp.dump(1) + "\n");
  if (recorded_outputs) {
    for (const nlohmann::json& f : stamp["outputs"]) {
      (*recorded_outputs)[resolved_path(f["path"].get<std::string>(), roots.outputs)] = f["hash"].get<std::string>();
    }
  }
  return {};
}

Status write_stamp(const Job& job, const std::vector<StampedFile>& read, const std::vector<StampedFile>& written,
                   const nlohmann::json& summary, const StampRoots& roots) {
  nlohmann::json inputs = nlohmann::json::array(), outputs = nlohmann::json::array();
  for (const StampedFile& f : read) inputs.push_back(stamped_file_json(f.identity, stamped_path(f.path, roots.inputs)));
  for (const StampedFile& f : written) outputs.push_back(stamped_file_json(f.identity, stamped_path(f.path, roots.outputs)));
  const nlohmann::json stamp = {{"form", kStampForm}, {"matbake", version}, {"job", job.name},   {"options", job.options},
                                {"inputs", inputs},    {"outputs", outputs},  {"summary", summary}};
  std::error_code ec;
  fs::create_directories(roots.state_folder, ec);
  // The summary's texts (warnings, file names in the details) are for reading: bytes that are not
  // UTF-8 (a path of another encoding) are replaced there; the stamp's own paths are encoded.
  return write_file_atomically(stamp_path(job.name, roots), stamp.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

std::optional<JobSummary> recorded_summary(const std::string& job_name, const StampRoots& roots) {
  const StateText read = read_state_file(stamp_path(job_name, roots), kStampLimit);
  if (!read.problem.empty() || read.absent) return std::nullopt;
  const nlohmann::json& stamp = read.json;
  if (!stamp.is_object() || !stamp.contains("summary") || !stamp["summary"].is_object()) return std::nullopt;
  const nlohmann::json& s = stamp["summary"];
  if (!s.contains("seconds") || !s["seconds"].is_number() || !s.contains("details") || !s.contains("warnings") ||
      !s["warnings"].is_array()) {
    return std::nullopt;
  }
  JobSummary out{s["seconds"].get<double>(), s["details"], {}};
  for (const nlohmann::json& w : s["warnings"]) {
    if (w.is_string()) out.warnings.push_back(w.get<std::string>());
  }
  return out;
}

void remove_stamp(const std::string& job_name, const StampRoots& roots) {
  std::error_code ec;
  fs::remove(stamp_path(job_name, roots), ec);
}

namespace {
fs::path failure_path(const std::string& job_name, const StampRoots& roots) {
  return roots.state_folder / (job_file_stem(job_name) + ".failed");
}
}  // namespace

void record_failure(const std::string& job_name, const Error& error, const StampRoots& roots) {
  std::error_code ec;
  fs::create_directories(roots.state_folder, ec);
  const nlohmann::json record = {{"job", job_name}, {"matbake", version}, {"error", error.to_string()}};
  (void)write_file_atomically(failure_path(job_name, roots), record.dump(1) + "\n");
}

void remove_failure(const std::string& job_name, const StampRoots& roots) {
  std::error_code ec;
  fs::remove(failure_path(job_name, roots), ec);
}

std::optional<std::string> recorded_failure(const std::string& job_name, const StampRoots& roots) {
  const StateText read = read_state_file(failure_path(job_name, roots), kStampLimit);
  if (!read.problem.empty() || read.absent) return std::nullopt;  // a bad record is as none: "not built"
  const nlohmann::json& record = read.json;
  if (!record.is_object() || !record.contains("error") || !record["error"].is_string()) return std::nullopt;
  return record["error"].get<std::string>();
}

}  // namespace matbake::pipeline
