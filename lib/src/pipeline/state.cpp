#include "matbake/read_file.hpp"
#include "state.hpp"

#include <nlohmann/json.hpp>
#include <xxhash.h>

#include <fstream>
#include <sstream>

#include "matbake/atomic_file.hpp"
#include "matbake/version.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

struct FileState {
  bool exists = false;
  std::uintmax_t size = 0;
  std::int64_t mtime = 0;  // nanoseconds, as the file system keeps them
};

FileState state_of(const fs::path& p) {
  std::error_code ec;
  FileState s;
  s.size = fs::file_size(p, ec);
  if (ec) return s;
  const auto time = fs::last_write_time(p, ec);
  if (ec) return s;
  s.exists = true;
  s.mtime = std::int64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count());
  return s;
}

std::string content_hash(const fs::path& p) {
  std::string b;  // a source that is not a regular file hashes as empty (its read refuses it)
  if (!read_whole_file(p, b)) b.clear();
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)XXH64(b.data(), b.size(), 0));
  return hex;
}

// The form of a stamp's options: raised when the same manifest is recorded differently (2: options
// by their parameter descriptions' names, sorted), so that an older stamp says why it rebuilds
// once rather than "its options changed".
constexpr int kStampForm = 2;

fs::path stamp_path(const Job& job, const fs::path& state_folder) {
  return state_folder / (job_file_stem(job) + ".json");
}

}  // namespace

std::string job_file_stem(const Job& job) {
  std::string stem = job.name;
  stem[stem.find(':')] = '-';
  return stem;
}

std::string out_of_date_reason(const Job& job, const fs::path& state_folder, bool refresh) {
  std::ifstream in(stamp_path(job, state_folder));
  if (!in) return "no earlier build";
  nlohmann::json stamp = nlohmann::json::parse(in, nullptr, false);
  if (stamp.is_discarded() || !stamp.is_object()) return "its stamp is unreadable";
  if (stamp.value("form", 1) != kStampForm) return "its stamp is from an older matbake (options recorded anew)";
  if (stamp.value("matbake", "") != version) return "matbake's version changed";
  if (stamp.value("options", "") != job.options) return "its options changed";
  const nlohmann::json inputs = stamp.value("inputs", nlohmann::json::array());
  std::vector<fs::path> recorded;
  for (const nlohmann::json& f : inputs) recorded.push_back(f.value("path", ""));
  for (const fs::path& p : job.inputs) {
    if (std::find(recorded.begin(), recorded.end(), p) == recorded.end()) return "new input: " + p.string();
  }
  bool touched = false;
  for (nlohmann::json& f : stamp["inputs"]) {
    const fs::path p = f.value("path", "");
    const FileState now = state_of(p);
    if (!now.exists) return "input missing: " + p.string();
    if (now.size == f.value("size", std::uintmax_t(0)) && now.mtime == f.value("mtime", std::int64_t(0))) continue;
    if (content_hash(p) != f.value("hash", "")) return "input changed: " + p.string();
    f["mtime"] = now.mtime;
    touched = true;
  }
  for (const nlohmann::json& f : stamp.value("outputs", nlohmann::json::array())) {
    const fs::path p = f.value("path", "");
    const FileState now = state_of(p);
    if (!now.exists) return "output missing: " + p.string();
    if (now.size != f.value("size", std::uintmax_t(0)) || now.mtime != f.value("mtime", std::int64_t(0))) {
      return "output changed since it was built: " + p.string();
    }
  }
  // Best effort: a stamp that cannot be written again only costs the next run some hashing.
  if (touched && refresh) (void)write_file_atomically(stamp_path(job, state_folder), stamp.dump(1) + "\n");
  return {};
}

Status write_stamp(const Job& job, const std::vector<fs::path>& read, const std::vector<fs::path>& written,
                   const fs::path& state_folder) {
  nlohmann::json inputs = nlohmann::json::array(), outputs = nlohmann::json::array();
  for (const fs::path& p : read) {
    const FileState s = state_of(p);
    inputs.push_back({{"path", p.string()}, {"size", s.size}, {"mtime", s.mtime}, {"hash", content_hash(p)}});
  }
  for (const fs::path& p : written) {
    const FileState s = state_of(p);
    outputs.push_back({{"path", p.string()}, {"size", s.size}, {"mtime", s.mtime}});
  }
  const nlohmann::json stamp = {
      {"form", kStampForm}, {"matbake", version}, {"job", job.name}, {"options", job.options}, {"inputs", inputs}, {"outputs", outputs}};
  std::error_code ec;
  fs::create_directories(state_folder, ec);
  return write_file_atomically(stamp_path(job, state_folder), stamp.dump(1) + "\n");
}

void remove_stamp(const Job& job, const fs::path& state_folder) {
  std::error_code ec;
  fs::remove(stamp_path(job, state_folder), ec);
}

}  // namespace matbake::pipeline
