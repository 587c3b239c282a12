#pragma once
// Stamps: what each job's last successful run read and wrote, kept in <output>/.matbake/, so a
// job runs again only when an input's content, its options or matbake's version changed, or an
// output is missing or was changed by someone else. Paths in a stamp are relative to the
// manifest's folder (inputs) and the output folder (outputs), so a moved or copied tree with the
// same bytes is up to date.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "matbake/pipeline.hpp"

namespace matbake::pipeline {

std::string job_file_stem(const std::string& job_name);  // "material-wood": the stamp's and the depfile's name
// Where a material's layout textures go: OUT/materials/NAME_{texture}.FORMAT.
std::filesystem::path material_texture_pattern(const Manifest& manifest, const MaterialSpec& m);
// The image files a material decodes (absolute, sorted, each once).
std::vector<std::filesystem::path> decoded_files(const MaterialSpec& m);
// The maps a material has: its sources, or its packed layout's.
material::MapNames source_map_names(const MaterialSpec& m);

// A file as a job read it: its size and modification time (nanoseconds) and the XXH64 of the bytes.
struct FileIdentity {
  std::uintmax_t size = 0;
  std::int64_t mtime = 0;
  std::string hash;  // 16 hex digits
};

std::string content_hash(std::span<const unsigned char> bytes);
// Size and modification time (nanoseconds since 1970) in one system call; empty when missing.
struct FileStat {
  std::uintmax_t size = 0;
  std::int64_t mtime = 0;
};
std::optional<FileStat> stat_file(const std::filesystem::path& file);
std::optional<std::int64_t> modification_time(const std::filesystem::path& file);
// The time first, then the bytes: a write in between leaves a time that differs from the file's
// next time, and the hash then decides. Empty when the file cannot be read.
std::optional<FileIdentity> identify(const std::filesystem::path& file);
// Whether the file is no longer what `read` says (the size or time differ and so do the bytes).
bool changed_since(const std::filesystem::path& file, const FileIdentity& read);

// matbake's state files (stamps, made.json, failure records, owner files) are read as hostile
// input: a link, a file that is not regular or one over `limit` bytes is refused before it is read,
// and its JSON is parsed only within kJsonDepthLimit (io/bounded_json.hpp).
struct StateText {
  std::string text;     // the bytes, when read
  nlohmann::json json;  // what they hold, when read and valid JSON within the limits
  std::string problem;  // why it was refused, could not be read or parsed (empty: read, or absent)
  bool absent = false;  // no such file: not a problem
};
StateText read_state_file(const std::filesystem::path& file, std::size_t limit);
// A job's options as a stamp holds them (JSON in a text), read as outside input: null when not
// JSON within the limits.
nlohmann::json options_json(const std::string& text);
inline constexpr std::size_t kStampLimit = 16u << 20;    // a scene with thousands of images: ~1 MB
inline constexpr std::size_t kMadeLogLimit = 64u << 20;  // 100,000 files: ~10 MB

struct StampedFile {
  std::filesystem::path path;  // absolute
  FileIdentity identity;
};

struct StampRoots {
  std::filesystem::path state_folder;  // <output>/.matbake
  std::filesystem::path inputs;        // the manifest's folder
  std::filesystem::path outputs;       // the output folder
};

// Why the job must run, or empty when it is up to date. A file whose size and modification time are
// as recorded is taken as unchanged; otherwise its content hash decides (a touched file, a fresh
// checkout or a copied tree does not rebuild). With `refresh`, the stamp of an up-to-date job takes
// the new times, so that the next run need not hash those files again.
// `recorded` (when given) receives the stamp's outputs with their hashes when the job is up to date.
// A reason that begins so says the stamp was refused (named, with why): the run warns of it.
// `changed` (when given) receives each option that differs: [{"parameter", "old", "new"}].
inline constexpr const char* kBadStamp = "stamp refused: ";
std::string out_of_date_reason(const Job& job, const StampRoots& roots, bool refresh,
                               std::map<std::filesystem::path, std::string>* recorded = nullptr,
                               nlohmann::json* changed = nullptr);

// The files as they are now; an error names the first that cannot be read.
Result<std::vector<StampedFile>> identify_all(const std::vector<std::filesystem::path>& files);

// Records a successful run: the inputs as they were read, the outputs as they were written.
// `summary`: what its run reported (time, details, warnings), for a report page of a later run
// that finds the job up to date.
Status write_stamp(const Job& job, const std::vector<StampedFile>& read, const std::vector<StampedFile>& written,
                   const nlohmann::json& summary, const StampRoots& roots);
struct JobSummary {
  double seconds = 0;
  nlohmann::json details;
  std::vector<std::string> warnings;
};
// The summary its stamp records (type-checked), or none.
std::optional<JobSummary> recorded_summary(const std::string& job_name, const StampRoots& roots);

// Removes the stamp, so that a failed job runs again next time.
void remove_stamp(const std::string& job_name, const StampRoots& roots);

// A failed run's error line, kept beside the stamps until the job runs again: what `build --status`
// reports of a job that ran elsewhere (a cluster node) and failed. Best effort: a record that cannot
// be written leaves the job "not built" in the status, never up to date.
void record_failure(const std::string& job_name, const Error& error, const StampRoots& roots);
void remove_failure(const std::string& job_name, const StampRoots& roots);
std::optional<std::string> recorded_failure(const std::string& job_name, const StampRoots& roots);

// Checks, and unless the folder is someone else's records (`record`), that the output folder belongs
// to this manifest (OUT/.matbake/owner.json; owner.cpp). An error names both manifests.
Status claim_output_folder(const Manifest& manifest, const Plan& plan, bool record, std::vector<std::string>& warnings);

// A path as a stamp or the state folder's logs hold it: relative to `root` where it lies below or
// beside it; and back.
std::string stamped_path(const std::filesystem::path& p, const std::filesystem::path& root);
std::filesystem::path resolved_path(const std::string& stamped, const std::filesystem::path& root);

}  // namespace matbake::pipeline
