#include "state.hpp"

#include <nlohmann/json.hpp>
#include <sys/stat.h>
#include <xxhash.h>

#include "matbake/atomic_file.hpp"
#include "matbake/read_file.hpp"
#include "matbake/version.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

// The form of a stamp: raised when the same manifest is recorded differently (2: options by their
// parameter descriptions' names, sorted; 3: paths relative to the manifest's and output folders,
// outputs hashed), so that an older stamp says why it rebuilds once rather than "its options changed".
constexpr int kStampForm = 3;

fs::path stamp_path(const std::string& job_name, const StampRoots& roots) {
  return roots.state_folder / (job_file_stem(job_name) + ".json");
}

nlohmann::json stamped_file_json(const FileIdentity& f, const std::string& path) {
  return {{"path", path}, {"size", f.size}, {"mtime", f.mtime}, {"hash", f.hash}};
}

FileIdentity identity_in(const nlohmann::json& f) {
  return {f.value("size", std::uintmax_t(0)), f.value("mtime", std::int64_t(0)), f.value("hash", "")};
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

std::string content_hash(std::span<const unsigned char> bytes) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)XXH64(bytes.data(), bytes.size(), 0));
  return hex;
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
  const std::optional<std::int64_t> mtime = modification_time(file);
  std::vector<unsigned char> bytes;
  if (!mtime || !read_whole_file(file, bytes)) return std::nullopt;
  return FileIdentity{bytes.size(), *mtime, content_hash(bytes)};
}

bool changed_since(const fs::path& file, const FileIdentity& read) {
  const std::optional<FileStat> s = stat_file(file);
  if (s && s->size == read.size && s->mtime == read.mtime) return false;
  const std::optional<FileIdentity> now = identify(file);
  return !now || now->hash != read.hash;
}

std::string out_of_date_reason(const Job& job, const StampRoots& roots, bool refresh, std::map<fs::path, std::string>* recorded_outputs) {
  std::string text;
  if (!read_whole_file(stamp_path(job.name, roots), text)) return "no earlier build";
  nlohmann::json stamp = nlohmann::json::parse(text, nullptr, false);
  if (stamp.is_discarded() || !stamp.is_object()) return "its stamp is unreadable";
  if (stamp.value("form", 1) != kStampForm) return "its stamp is from an older matbake (recorded anew)";
  if (stamp.value("matbake", "") != version) return "matbake's version changed";
  if (stamp.value("options", "") != job.options) return "its options changed";
  if (!stamp["inputs"].is_array() || !stamp["outputs"].is_array()) return "its stamp is unreadable";
  std::vector<fs::path> recorded;
  for (const nlohmann::json& f : stamp["inputs"]) recorded.push_back(resolved_path(f.value("path", ""), roots.inputs));
  for (const fs::path& p : job.inputs) {
    if (std::find(recorded.begin(), recorded.end(), p) == recorded.end()) return "new input: " + p.string();
  }
  bool touched = false;
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    std::string why = check_recorded(stamp["inputs"][i], recorded[i], "input missing: ", "input changed: ", touched);
    if (!why.empty()) return why;
  }
  for (nlohmann::json& f : stamp["outputs"]) {
    const fs::path p = resolved_path(f.value("path", ""), roots.outputs);
    std::string why = check_recorded(f, p, "output missing: ", "output changed since it was built: ", touched);
    if (!why.empty()) return why;
  }
  // Best effort: a stamp that cannot be written again only costs the next run some hashing.
  if (touched && refresh) (void)write_file_atomically(stamp_path(job.name, roots), stamp.dump(1) + "\n");
  if (recorded_outputs) {
    for (const nlohmann::json& f : stamp["outputs"]) {
      (*recorded_outputs)[resolved_path(f.value("path", ""), roots.outputs)] = f.value("hash", "");
    }
  }
  return {};
}

Status write_stamp(const Job& job, const std::vector<StampedFile>& read, const std::vector<StampedFile>& written,
                   const StampRoots& roots) {
  nlohmann::json inputs = nlohmann::json::array(), outputs = nlohmann::json::array();
  for (const StampedFile& f : read) inputs.push_back(stamped_file_json(f.identity, stamped_path(f.path, roots.inputs)));
  for (const StampedFile& f : written) outputs.push_back(stamped_file_json(f.identity, stamped_path(f.path, roots.outputs)));
  const nlohmann::json stamp = {{"form", kStampForm}, {"matbake", version}, {"job", job.name},
                                {"options", job.options}, {"inputs", inputs},   {"outputs", outputs}};
  std::error_code ec;
  fs::create_directories(roots.state_folder, ec);
  return write_file_atomically(stamp_path(job.name, roots), stamp.dump(1) + "\n");
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
  std::string text;
  if (!read_whole_file(failure_path(job_name, roots), text)) return std::nullopt;
  const nlohmann::json record = nlohmann::json::parse(text, nullptr, false);
  if (!record.is_object() || !record.contains("error") || !record["error"].is_string()) return std::nullopt;
  return record["error"].get<std::string>();
}

}  // namespace matbake::pipeline
