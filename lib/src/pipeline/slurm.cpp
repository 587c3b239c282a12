#include <algorithm>
#include <cctype>
#include <map>

#include "matbake/atomic_file.hpp"
#include "matbake/cluster.hpp"
#include "matbake/output_check.hpp"
#include "matbake/image.hpp"
#include "matbake/script_text.hpp"
#include "matbake/version.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

// An argument of an sbatch line: literal text, or the array's job id that the script learns when it
// runs ("$array"). Never a literal text read for a variable: a path holding "$array" stays a path.
struct Part {
  std::string text;
  bool array_id = false;
};
using Word = std::vector<Part>;

Word literal(std::string text) { return {Part{std::move(text)}}; }

Word mem_argument(std::int64_t mb) { return literal("--mem=" + std::to_string(mb) + "M"); }

// --output's file in `folder`: Slurm expands %-patterns, so the folder's own % are written %%.
Word log_pattern(const fs::path& folder, const std::string& file_pattern) {
  std::string out = "--output=";
  for (char c : (folder / "logs").string() + "/") out += c == '%' ? std::string("%%") : std::string(1, c);
  return literal(out + file_pattern);
}

// What every sbatch call asks for besides its own job: cores, the options' partition, account, time.
void add_common_arguments(std::vector<Word>& args, const ClusterOptions& options) {
  args.push_back(literal("--cpus-per-task=" + std::to_string(options.cpus)));
  if (!options.partition.empty()) args.push_back(literal("--partition=" + options.partition));
  if (!options.account.empty()) args.push_back(literal("--account=" + options.account));
  if (!options.time_limit.empty()) args.push_back(literal("--time=" + options.time_limit));
}

std::vector<Word> array_command(const SlurmSubmission& s, const ClusterOptions& options, const SlurmTarget& target) {
  std::string range = "0-" + std::to_string(s.array.size() - 1);
  if (options.array_throttle > 0) range += "%" + std::to_string(options.array_throttle);
  std::vector<Word> args{literal("--parsable"), literal("--job-name=matbake-materials"), literal("--array=" + range),
                         mem_argument(s.array_memory_mb)};
  add_common_arguments(args, options);
  args.push_back(log_pattern(target.folder, "material-%a.log"));
  args.push_back(literal((target.folder / "job.sh").string()));
  return args;
}

std::vector<Word> scene_command(const SlurmJob& scene, const ClusterOptions& options, const SlurmTarget& target) {
  std::vector<Word> args{literal("--parsable"), literal("--job-name=matbake-" + scene.job->name)};
  if (!scene.after.empty()) {
    Word dependency = literal("--dependency=afterok");
    for (std::size_t task : scene.after) {
      dependency.push_back({":"});
      dependency.push_back({"", true});
      std::string part = "_";  // appended, not `"_" + to_string(...)`: GCC 12 at -O3 warns falsely on that
      part += std::to_string(task);
      dependency.push_back({std::move(part)});
    }
    args.push_back(std::move(dependency));
    // A failed material cancels the scenes that wait for it (else they would wait for ever).
    args.push_back(literal("--kill-on-invalid-dep=yes"));
  }
  args.push_back(mem_argument(scene.memory_mb));
  add_common_arguments(args, options);
  args.push_back(log_pattern(target.folder, job_file_stem(scene.job->name) + ".log"));
  args.push_back(literal((target.folder / "job.sh").string()));
  args.push_back(literal(scene.job->name));
  return args;
}

// The word as the script holds it: literal parts quoted, the array id as "$array".
Result<std::string> script_word(const Word& word) {
  std::string out;
  for (const Part& part : word) {
    if (part.array_id) {
      out += "\"$array\"";
    } else if (std::string problem = unscriptable(part.text); !problem.empty()) {
      return Error{part.text, problem + "; a shell script cannot hold it", true};
    } else if (!part.text.empty()) {
      out += shell_word(part.text);
    }
  }
  return out;
}

}  // namespace

SlurmSubmission slurm_submission(const Plan& plan, const Report& dry_run, const ClusterOptions& options,
                                 const std::function<JobFootprint(const Job&)>& footprint_of) {
  const auto memory_for = [&](const Job& job) {
    const std::int64_t of_kind = job.kind == JobKind::material ? options.material_memory_mb : options.scene_memory_mb;
    if (of_kind > 0) return of_kind;
    return options.memory_mb > 0 ? options.memory_mb : memory_request_mb(footprint_of(job));
  };
  SlurmSubmission s;
  std::map<std::string, std::size_t> task_of;  // material job name → array index
  for (const JobReport& r : dry_run.jobs) {
    if (r.job->kind != JobKind::material || r.outcome == Outcome::up_to_date) continue;
    task_of[r.job->name] = s.array.size();
    s.array.push_back({r.job, memory_for(*r.job), {}});
    s.array_memory_mb = std::max(s.array_memory_mb, s.array.back().memory_mb);
  }
  for (const JobReport& r : dry_run.jobs) {
    if (r.job->kind != JobKind::scene) continue;
    SlurmJob scene{r.job, 0, {}};
    for (const std::string& name : r.job->depends_on) {
      if (const auto t = task_of.find(name); t != task_of.end()) scene.after.push_back(t->second);
    }
    if (r.outcome == Outcome::up_to_date && scene.after.empty()) continue;
    scene.memory_mb = memory_for(*r.job);
    s.scenes.push_back(std::move(scene));
  }
  s.up_to_date = plan.jobs.size() - s.array.size() - s.scenes.size();
  return s;
}

Result<std::vector<std::string>> sbatch_lines(const SlurmSubmission& submission, const ClusterOptions& options,
                                              const SlurmTarget& target, const std::string& program) {
  std::vector<std::vector<Word>> commands;
  if (!submission.array.empty()) commands.push_back(array_command(submission, options, target));
  for (const SlurmJob& scene : submission.scenes) commands.push_back(scene_command(scene, options, target));
  std::vector<std::string> lines;
  for (const auto& args : commands) {
    std::string line = program;
    for (const Word& a : args) {
      auto word = script_word(a);
      if (!word) return word.error();
      line += " " + *word;
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

std::string submission_counts(const SlurmSubmission& submission) {
  return std::to_string(submission.array.size()) + " material jobs (one array), " + std::to_string(submission.scenes.size()) +
         (submission.scenes.size() == 1 ? " scene job; " : " scene jobs; ") + std::to_string(submission.up_to_date) +
         " up to date";
}

Result<SlurmScripts> slurm_scripts(const Manifest& manifest, const SlurmSubmission& submission, const ClusterOptions& options,
                                   const SlurmTarget& target) {
  // Every path and name the scripts hold, refused before anything is written when a line break
  // would end a comment or a command.
  std::vector<std::string> words{manifest.file.native(), manifest.output.native(), target.folder.native(), target.matbake.native()};
  for (const SlurmJob& j : submission.array) words.push_back(j.job->name);
  for (const std::string& w : words) {
    if (std::string problem = unscriptable(w); !problem.empty()) return Error{w, problem + "; a shell script cannot hold it", true};
  }
  auto lines = sbatch_lines(submission, options, target, "\"$sbatch\"");
  if (!lines) return lines.error();
  const std::string header = "#!/usr/bin/env bash\n# Written by `matbake plan --format slurm` (matbake " +
                             std::string(version) + ") from " + shell_word(manifest.file.native()) + ".\n";
  SlurmScripts out;
  out.job = header +
            "# One job on a Slurm node: the material of this array task, or the job named as the argument\n"
            "# (a scene). It builds and stamps as `matbake build --only JOB` does on any machine.\n"
            "set -euo pipefail\nmaterials=(";
  for (const SlurmJob& j : submission.array) out.job += (&j == submission.array.data() ? "" : " ") + shell_word(j.job->name);
  out.job += ")\njob=${1:-${materials[$SLURM_ARRAY_TASK_ID]}}\nexec " + shell_word(target.matbake.string()) +
             " --jobs " + std::to_string(options.cpus) + " build " + shell_word(manifest.file.string()) +
             " --output-dir " + shell_word(manifest.output.string()) + " --only \"$job\"\n";

  const std::string counts = submission_counts(submission);
  out.submit = header + "# " + counts +
               ".\n# Run it where sbatch works; every path is absolute (a filesystem every node shares). Then\n"
               "# `matbake build " + shell_word(manifest.file.string()) + " --status` tells how the jobs went.\n"
               "set -euo pipefail\n";
  if (submission.array.empty() && submission.scenes.empty()) {
    out.submit += "echo " + shell_word("matbake: nothing to submit: " + counts) + "\n";
    return out;
  }
  out.submit += "sbatch=${SBATCH:-sbatch}\nmkdir -p " + shell_word((target.folder / "logs").string()) + "\n";
  std::size_t next = 0;
  if (!submission.array.empty()) {
    out.submit += "array=$(" + (*lines)[next++] + ")\narray=${array%%;*}  # --parsable: id[;cluster]\n";
  }
  std::string ids;
  for (; next < lines->size(); ++next) {
    const std::string var = "scene_" + std::to_string(next);
    out.submit += var + "=$(" + (*lines)[next] + ")\n";
    ids += " $" + var;
  }
  out.submit += "echo \"matbake: submitted " + counts + ":" + (submission.array.empty() ? "" : " array $array") +
                (ids.empty() ? "" : " scenes" + ids) + "\"\n";
  return out;
}

Status write_slurm_scripts(const Manifest& manifest, const Plan& plan, const SlurmScripts& scripts, const fs::path& folder) {
  const NamedOutput outputs[] = {{folder / "submit.sh", "-o"}, {folder / "job.sh", "-o"}};
  if (Status st = check_side_outputs(manifest, plan, outputs); !st) return st;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) return Error{folder.string(), "cannot make the folder: " + ec.message()};
  for (const auto& [output, text] : {std::pair{outputs[0].path, &scripts.submit}, std::pair{outputs[1].path, &scripts.job}}) {
    if (Status st = write_file_atomically(output, *text); !st) return st;
    fs::permissions(output, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec, fs::perm_options::add, ec);
  }
  return success();
}

nlohmann::json slurm_json(const SlurmSubmission& submission, const ClusterOptions& options, const SlurmTarget& target,
                          bool dry_run, const std::vector<std::string>& sbatch) {
  nlohmann::json doc = {{"format", "slurm"}, {"folder", target.folder}, {"dry_run", dry_run},
                        {"up_to_date", submission.up_to_date}, {"cluster", params::to_json(cluster_params(), options)},
                        {"sbatch", sbatch}};
  doc["array"] = {{"memory_mb", submission.array_memory_mb}, {"jobs", nlohmann::json::array()}};
  doc["array"]["task_memory_mb"] = nlohmann::json::array();  // each task's own estimate (or setting)
  for (const SlurmJob& j : submission.array) {
    doc["array"]["jobs"].push_back(j.job->name);
    doc["array"]["task_memory_mb"].push_back(j.memory_mb);
  }
  doc["scenes"] = nlohmann::json::array();
  for (const SlurmJob& j : submission.scenes) {
    doc["scenes"].push_back({{"job", j.job->name}, {"memory_mb", j.memory_mb}, {"after_tasks", j.after}});
  }
  return doc;
}

}  // namespace matbake::pipeline
