#pragma once
// `matbake plan --format slurm`: a manifest's out-of-date jobs handed to a Slurm cluster. The
// material jobs go as one job array, and each scene job waits for exactly the array tasks whose
// outputs it reads. Every task runs `matbake build MANIFEST --only JOB`, so a cluster run writes
// and stamps as a local build does, and either is up to date after the other (docs/cluster.md).
#include <cstdint>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "matbake/params.hpp"
#include "matbake/pipeline.hpp"

namespace matbake::pipeline {

// partition, account, time_limit, array_throttle, memory_mb (flags of `plan` and the manifest's
// [cluster] table) and cpus (the manifest's; `plan --jobs` sets it too).
const params::Group<ClusterOptions>& cluster_params();

// What a job holds at its peak, in bytes, by part (docs/cluster.md, "Memory model"): counted from
// what it decodes, makes and writes, as scripts/bench-cluster.sh measured those to cost.
struct JobFootprint {
  double program = 0;   // the program and its libraries
  double images = 0;    // decoded sources, a material's maps, the textures it makes (float samples)
  double geometry = 0;  // a scene's buffers, meshes and ray-tracing structure
  double ao = 0;        // a scene's AO textures being baked
  double encoder = 0;   // KTX2: the textures encoded at once, basisu's own memory included
  double total() const { return program + images + geometry + ao + encoder; }
};
// `cpus`: the cores the job runs with (a KTX2 scene encodes that many textures at once).
JobFootprint job_footprint(const Job& job, const Manifest& manifest, int cpus);
// The request for a footprint: a quarter on top (Slurm ends a job that passes its request),
// rounded up to a multiple of 64 MB.
std::int64_t memory_request_mb(const JobFootprint& footprint);

// One job as it is submitted.
struct SlurmJob {
  const Job* job = nullptr;
  std::int64_t memory_mb = 0;        // asked for: the options' (its kind's, else every job's), else the model's
  std::vector<std::size_t> after;    // a scene: the array tasks (indices) whose outputs it reads
};

struct SlurmSubmission {
  std::vector<SlurmJob> array;    // the material jobs: array task i runs array[i]
  std::int64_t array_memory_mb = 0;  // every task's (Slurm gives an array one size): the largest
  std::vector<SlurmJob> scenes;   // each after its tasks
  std::size_t up_to_date = 0;     // jobs left out
};

// The jobs a dry run found out of date (or failing: they run and fail where the status shows
// them), and every scene that reads a material submitted with them. `footprint_of` gives a job's
// footprint (job_footprint, in practice), used where the options set no memory for its kind.
SlurmSubmission slurm_submission(const Plan& plan, const Report& dry_run, const ClusterOptions& options,
                                 const std::function<JobFootprint(const Job&)>& footprint_of);

// Where the submission runs and what it runs.
struct SlurmTarget {
  std::filesystem::path folder;   // the scripts and logs/ (absolute)
  std::filesystem::path matbake;  // the program every node runs (absolute, on the shared filesystem)
};

// The sbatch command of each submission as a shell line, in order (the array first, then the
// scenes); a scene's dependency names the array by "$array" (its job id, known when the script runs).
// `program` starts each line: sbatch, or submit.sh's "$sbatch" (a stand-in the tests set).
// Every word is quoted by shell_word (script_text.hpp); an error (usage) for a path or name the
// shell script cannot hold (a line break).
Result<std::vector<std::string>> sbatch_lines(const SlurmSubmission& submission, const ClusterOptions& options,
                                              const SlurmTarget& target, const std::string& program = "sbatch");

// "5 material jobs (one array), 1 scene job; 0 up to date"
std::string submission_counts(const SlurmSubmission& submission);

// The two scripts written to target.folder: submit.sh (run where sbatch works: it submits the
// array and the scenes, chaining their job ids) and job.sh (what each job runs).
struct SlurmScripts {
  std::string submit;
  std::string job;
};
Result<SlurmScripts> slurm_scripts(const Manifest& manifest, const SlurmSubmission& submission, const ClusterOptions& options,
                                   const SlurmTarget& target);

// submit.sh and job.sh written into `folder` (made if need be, executable); neither may be a file the
// build reads or writes.
Status write_slurm_scripts(const Manifest& manifest, const Plan& plan, const SlurmScripts& scripts,
                           const std::filesystem::path& folder);

// `plan --format slurm --json`: the folder, the settings, the sbatch lines, the array's tasks with each
// one's memory, the scenes with theirs and the tasks they wait for.
nlohmann::json slurm_json(const SlurmSubmission& submission, const ClusterOptions& options, const SlurmTarget& target,
                          bool dry_run, const std::vector<std::string>& sbatch);

}  // namespace matbake::pipeline
