#pragma once
// `matbake build`: a TOML manifest of materials and scenes, built the way a build tool builds.
// - A material's sources are decoded (convert), converted to the workflow its layout needs
//   (workflow), packed into the layout's textures (pack) and checked (validate); a scene is written
//   again as glTF 2.0 with those materials and per-vertex AO (bake-ao, export).
// - Each output job runs only when it is out of date: a stamp beside the outputs records its
//   inputs (size, time, content hash), its options and matbake's version.
// - Jobs run in parallel (TBB), each source file is decoded once however many jobs read it, and a
//   failing job does not stop the others.
// - The build keeps a log of the files it made; after a full run with no failure, those no job
//   makes now are removed (docs/build.md).
// docs/build.md has the manifest's schema.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "matbake/ao.hpp"
#include "matbake/bake_file.hpp"
#include "matbake/enum_names.hpp"
#include "matbake/export.hpp"
#include "matbake/image.hpp"
#include "matbake/output_check.hpp"
#include "matbake/output_gate.hpp"
#include "matbake/pack.hpp"
#include "matbake/result.hpp"
#include "matbake/validate.hpp"
#include "matbake/workflow.hpp"

namespace matbake::pipeline {

struct ValidationRules {
  bool enabled = true;
  validate::Options options;  // tolerance (against `reference`), max_violations (else the job fails), worst_count
  bool heatmap = false;       // also write <name>_validation.png
};

// Where each value of a manifest entry was written ("assets.toml:12:5"), by its key within the
// entry ("layout", "sources.kd", "packed.files", "reference"; "" for the entry itself), so that an
// error found while planning or running a job names the line at fault.
struct Origins {
  std::map<std::string, std::string> by_key;
  const std::string& of(const std::string& key) const;  // the key's, else the entry's
};

// A layout the manifest names, resolved when the manifest is read (pack::resolve_layout, relative to
// the manifest's folder).
struct LayoutChoice {
  std::string reference;        // as written: a preset's name or a file
  pack::Layout layout;
  std::filesystem::path file;   // the layout file read (empty: a preset); an input of every job using it
};

struct MaterialSpec {
  std::string name;  // [A-Za-z0-9_.-], names its output files
  Origins origins;
  // Either separate source maps (files or constants) ...
  std::vector<pack::SourceInput> sources;
  // ... or the packed textures of a layout (e.g. a Schüler pair).
  std::optional<LayoutChoice> packed;
  std::vector<std::filesystem::path> packed_files;
  pack::MaterialOptions options;  // transfer, decode, resize, size, bits, format, mapping
  std::optional<LayoutChoice> layout;  // textures to write; unset: none
  image::Encoding encoding;  // png_compression
  std::string reference;  // a material table entry to validate against
  ValidationRules validation;
};

// A scene's `bake = { from = "high.glb", maps = [...], ... }`: the high-poly's maps baked onto the
// scene's glTF (matbake bake) before it is exported; its `ao` table is the ao and bent_normal maps'
// estimator.
struct SceneBake {
  std::string from;             // as written, relative to the manifest's folder
  std::filesystem::path high;   // resolved
  std::string cage_file;        // the cage mesh as written (empty: extrusion)
  std::filesystem::path cage;   // resolved
  bake::Request request;
};

struct SceneSpec {
  std::string name;
  Origins origins;
  std::filesystem::path input;   // .gltf or .glb
  std::filesystem::path output;  // inside the output folder
  std::map<std::string, std::string> materials;  // glTF material name → manifest material
  bool match_names = true;  // also: glTF materials named like a manifest material get it
  exporter::Options options;  // as `matbake export` fills it; its materials are added when the job runs
  std::optional<SceneBake> bake;  // set: the input is baked onto first, and the export reads the bake
};

// A [material_rules.NAME] entry and the materials it made, one per file its pattern matched.
struct MaterialRule {
  std::string name;
  std::string origin;  // "assets.toml:12:1"
  std::vector<std::string> materials;
  std::filesystem::path folder;  // the folder its match scans (a new file there is a new material)
};

// The manifest's [cluster] table: what `plan --format slurm` asks sbatch for (matbake/cluster.hpp).
struct ClusterOptions {
  std::string partition;            // sbatch --partition; empty: the cluster's default
  std::string account;              // sbatch --account; empty: the user's default
  std::string time_limit;           // sbatch --time of each job ("30:00", "2:00:00"); empty: the partition's
  std::int64_t array_throttle = 0;  // at most this many material jobs at once (--array=...%N); 0: no limit
  std::int64_t memory_mb = 0;       // each job's memory; 0: the memory model's (job_footprint)
  std::int64_t material_memory_mb = 0;  // a material job's, over memory_mb; 0: memory_mb's
  std::int64_t scene_memory_mb = 0;     // a scene job's, over memory_mb; 0: memory_mb's
  std::int64_t cpus = 1;            // cores per job (--cpus-per-task); the job runs with --jobs this
};

struct Manifest {
  std::filesystem::path file;    // absolute
  std::filesystem::path folder;  // relative paths in the manifest resolve here
  std::filesystem::path output;  // absolute; everything is written inside it
  std::filesystem::path table;   // material table (empty: the built-in one)
  Origins origins;               // of the top-level keys ("table", "output", ...)
  std::vector<std::string> notes;  // older key names read, each with its line (printed as warnings)
  std::vector<MaterialSpec> materials;  // its own, then those its rules made
  std::vector<MaterialRule> rules;
  std::vector<SceneSpec> scenes;
  ClusterOptions cluster;
  // `shared_output = true`: other manifests (that say so too) build into the same output folder;
  // each keeps its own stamps and log (OUT/.matbake/shared/<its id>/) and cleans apart. Without
  // it the folder belongs to the manifest that built it first (OUT/.matbake/owner.json).
  bool shared_output = false;
  bool prune = false;  // `prune = true`: as --prune on every run (RunOptions::prune)
  bool report = false;  // `report = true`: every build writes OUT/report.html (write_report_page)
  // `max_pixels = N`: the largest image its jobs read or make (image::set_max_pixels), wherever they
  // run (a build, Ninja's or Slurm's jobs); 0: the run's own limit.
  std::int64_t max_pixels = 0;
};

// Errors name the manifest with line and column, and the key.
Result<Manifest> parse_manifest(std::string_view toml_text, const std::filesystem::path& file);
Result<Manifest> read_manifest(const std::filesystem::path& file);

enum class JobKind { material, scene };

// What a job writes, by role, as known before it runs (empty: not made by this job).
struct JobOutputs {
  std::vector<std::filesystem::path> textures;  // a material's layout textures, in the layout's order
  std::filesystem::path validation_report;      // <name>.validation.json
  std::filesystem::path heatmap;                // <name>_validation.png
  std::filesystem::path preview;                // a material's ball: <name>_preview.png (the report page's)
  std::filesystem::path scene;                  // a scene's .gltf or .glb
  std::filesystem::path buffer;                 // a .gltf scene's .bin
  std::vector<std::filesystem::path> all() const;  // every one, in that order
};

struct Job {
  JobKind kind = JobKind::material;
  std::size_t spec = 0;  // index into the manifest's materials or scenes
  std::string name;      // "material:wood", "scene:showroom"
  JobOutputs outputs;
  std::vector<std::filesystem::path> inputs;   // every file it reads
  std::map<std::string, std::size_t> materials;  // a scene: glTF material name → manifest material
  std::vector<std::string> depends_on;  // jobs that must succeed first (a scene: its materials' jobs)
  std::string options;   // what besides the inputs decides the outputs (canonical JSON)
  std::optional<Error> problem;  // found while planning (a file or table entry that is not there):
                                 // the job fails with it, in a dry run too
};

struct Plan {
  std::vector<Job> jobs;
  std::vector<std::string> warnings;  // e.g. a material nothing uses
  std::filesystem::path state_folder;  // the stamps: <output>/.matbake (shared: .matbake/shared/<id>)
  std::string owner;                   // the manifest as the output folder records it (owner.json)
};

// Which jobs the manifest makes and what each reads and writes (a scene's buffers and images are
// read from its JSON). Fails only for problems of the manifest as a whole (an output that is an
// input, two jobs writing one file).
Result<Plan> make_plan(const Manifest& manifest);

// skipped: a job it depends on failed in this run (as Make and Ninja do, it is not run).
enum class Outcome { built, up_to_date, failed, skipped, out_of_date /* --dry-run */ };
inline constexpr NameTable<Outcome, 5> kOutcomeNames{{{Outcome::built, "built"},
                                                      {Outcome::up_to_date, "up_to_date"},
                                                      {Outcome::failed, "failed"},
                                                      {Outcome::skipped, "skipped"},
                                                      {Outcome::out_of_date, "out_of_date"}}};

struct JobReport {
  const Job* job = nullptr;
  Outcome outcome = Outcome::up_to_date;
  std::string reason;  // why it ran: "no earlier build", "input changed: ...", "forced", ...
  nlohmann::json changed;  // when its options changed: [{"parameter", "old", "new"}], each one
  double seconds = 0;
  std::vector<std::string> warnings;
  std::optional<Error> error;
  nlohmann::json details;  // validation, conversion errors, the export report
  // Inputs that changed while the job ran: its outputs are from the bytes read before, as its stamp
  // records, so it runs again next time (the build says so and exits 1).
  std::vector<std::filesystem::path> moved;
  // Its outputs with their content hashes: as written (built) or as its stamp records them (up to date).
  std::map<std::filesystem::path, std::string> written;
};

// Files an earlier run made that no job of the manifest makes now (a material removed or renamed,
// its layout changed, validation turned off).
struct StaleOutputs {
  std::vector<std::filesystem::path> removed;  // at the end of a full run with no failure
  std::vector<std::filesystem::path> kept;     // --keep-stale, --only, a failed job or a dry run: removed later
  std::vector<std::filesystem::path> changed;  // changed since matbake wrote them: left alone, forgotten
  // Why nothing was removed although files are stale (too many at once without --prune), or empty.
  std::string held_back;
  // Entries of the log that do not provably name a file matbake made in the output folder (a path
  // out of it, through a link, an alias of a live output, an input): each with why; left alone,
  // forgotten.
  std::vector<std::string> refused;
};

inline constexpr double kPruneShare = 0.5;
inline constexpr std::size_t kPruneMinimum = 8;

class BuildProgress;

struct RunOptions {
  bool force = false;
  bool dry_run = false;
  std::vector<std::string> only;  // job names; empty: all
  bool keep_stale = false;        // keep the files no job makes now (else removed after a full run)
  // Allow what a lost input looks like: removing more than kPruneShare of the files made (and more
  // than kPruneMinimum), or a scene losing a manifest material it was built with. Without it
  // the run stops before building (a scene) or keeps the files (the share) and says why.
  bool prune = false;
  // Called as each job finishes (from worker threads, one call at a time).
  std::function<void(const JobReport&, std::size_t done, std::size_t total)> progress;
  // Told the jobs to run with their work, each job's start and stage, each job's end (from worker
  // threads); a display reads it (build_progress.hpp). Null: none.
  BuildProgress* tracker = nullptr;
  // Called when a job has written its outputs and before its stamp is (tests change a source here).
  std::function<void(const Job&)> before_stamp;
};

struct Report {
  std::vector<JobReport> jobs;  // in plan order
  std::size_t images_decoded = 0;
  StaleOutputs stale;
  std::vector<std::string> warnings;  // about the run as a whole
  std::size_t count(Outcome o) const;
  std::size_t moved() const;  // jobs with an input that changed while they ran
  std::size_t over_validation_limit() const;  // jobs whose advisory validation flagged more than allowed
};

// Runs the out-of-date jobs of the plan (all jobs with force). Errors are per job, in the report.
Result<Report> run(const Manifest& manifest, const Plan& plan, const RunOptions& options);

// What a scene job would deliver, without building (`matbake inspect MANIFEST`): its materials
// decoded and converted as the build would, AO textures made at their sizes (one ray a texel), then
// delivery's plan of every texture (exporter::Options::plan_only). Nothing is written.
Result<std::vector<delivery::TextureReport>> plan_scene(const Manifest& manifest, const Job& job);

// How each job stands after runs elsewhere (a cluster's jobs, each its own `build --only`), read
// from the stamps and the failures recorded beside them: up to date, failed (the error line of its
// last run) or not built (never run, running, cancelled, or out of date since it ran).
enum class JobState { up_to_date, failed, not_built };
inline constexpr NameTable<JobState, 3> kJobStateNames{
    {{JobState::up_to_date, "up_to_date"}, {JobState::failed, "failed"}, {JobState::not_built, "not_built"}}};
struct JobStatus {
  const Job* job = nullptr;
  JobState state = JobState::not_built;
  std::string detail;  // failed: the error line; not built: why ("no earlier build", "waits for material:x, which failed")
};
Result<std::vector<JobStatus>> job_statuses(const Manifest& manifest, const Plan& plan);
// `build --status --json`: the manifest, each job's state and detail, and the counts per state.
nlohmann::json status_json(const Manifest& manifest, const std::vector<JobStatus>& statuses);

// The run as `build --json` prints it (without "command", "dry_run" and "seconds"): the manifest,
// the output folder, each job (name, outcome, inputs, outputs, seconds, warnings, reason, error,
// details), the counts by outcome, images decoded and the plan's warnings.
nlohmann::json json_report(const Manifest& manifest, const Plan& plan, const Report& report);

// The gate of the plan's output folder: it protects the manifest and every input and output of
// every job (docs/reliability.md).
OutputGate output_gate(const Manifest& manifest, const Plan& plan);

// Files written on request beside a build (--depfile, --stamp, plan -o, a Slurm folder's scripts),
// checked before any work: none may be a file the build reads or writes, lie in the output
// folder's state folder, or be another of them. A usage error naming the option and the file.
Status check_side_outputs(const Manifest& manifest, const Plan& plan, std::span<const NamedOutput> outputs);

// What a build step leaves for the build tool that runs it (CMake, Ninja): a Make depfile of the
// manifest and every input the jobs read, whose targets are the jobs' outputs or, when given,
// `stamp`; and `stamp` itself (a line naming the manifest) once no job failed. Either path may
// be empty; a dry run should write neither.
Status write_build_tool_files(const Manifest& manifest, const Report& report, const std::filesystem::path& depfile,
                              const std::filesystem::path& stamp);

// `build --report`: one HTML page of the run at `page` (inside the output folder; a usage error
// otherwise), with each job (this run's outcome, or an up-to-date job's recorded summary), each
// material's textures, heatmap, validation and conversion error, each scene's AO textures and
// delivered textures (docs/build.md#the-report-page). Images are the output folder's files, linked
// relative to the page; a scene's PNG, JPEG and WebP images are copied into report/ beside it.
Status write_report_page(const Manifest& manifest, const Plan& plan, const Report& report, const std::filesystem::path& page);
// The page's place, checked before a build runs: inside the output folder, none of its files.
Status check_report_page(const Manifest& manifest, const Plan& plan, const std::filesystem::path& page);

// Make syntax: `targets: inputs`, spaces escaped, one prerequisite per line; an error (usage) for
// a path no depfile can hold (a line break).
Result<std::string> depfile_text(const std::vector<std::filesystem::path>& targets,
                                 const std::vector<std::filesystem::path>& inputs);

// Whether a depfile can list every file of the plan (the manifest, each job's inputs and outputs):
// checked before a build with --depfile runs, and by ninja_text.
Status check_depfile_paths(const Manifest& manifest, const Plan& plan);

// A Ninja file with one edge per job, each running `matbake build MANIFEST --only JOB`, with the
// job's depfile so Ninja also learns what it read, and an edge that writes `ninja_file` (absolute;
// named by its file name, as Ninja run in its folder names it) again when the manifest changes or
// a folder a material rule scans does (a new texture set). Every path
// and name goes through script_text.hpp: an error (usage) for one Ninja or the shell cannot hold.
Result<std::string> ninja_text(const Manifest& manifest, const Plan& plan, const std::filesystem::path& matbake,
                               const std::filesystem::path& ninja_file);

}  // namespace matbake::pipeline
