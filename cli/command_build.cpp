#include <unistd.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>

#include "commands.hpp"
#include "params_cli.hpp"
#include "matbake/join.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/cluster.hpp"
#include "matbake/image.hpp"
#include "matbake/output_check.hpp"
#include "matbake/pipeline.hpp"
#include "progress_bar.hpp"
#include "silenced_stderr.hpp"

namespace matbake::cli {
namespace fs = std::filesystem;
namespace {

std::string job_error(const pipeline::JobReport& r) { return r.error->to_string() + " (" + r.job->name + ")"; }

// The manifest and its plan; its pixel limit applies unless the command line gave one.
Result<pipeline::Plan> load(const std::string& manifest_file, const std::string& output_dir, const GlobalOptions& global,
                            pipeline::Manifest& manifest) {
  auto m = pipeline::read_manifest(manifest_file);
  if (!m) return m.error();
  manifest = std::move(*m);
  if (manifest.max_pixels > 0 && !global.max_pixels_given) image::set_max_pixels(std::uint64_t(manifest.max_pixels));
  if (!output_dir.empty()) manifest.output = fs::absolute(output_dir).lexically_normal();
  return pipeline::make_plan(manifest);
}

void print_stale(const pipeline::StaleOutputs& stale, bool dry_run) {
  for (const fs::path& p : stale.removed) std::printf("removed %s: no job makes it now\n", p.c_str());
  const char* kept = dry_run ? "would remove" : "kept";
  for (const fs::path& p : stale.kept) std::printf("%s %s: no job makes it now\n", kept, p.c_str());
  for (const fs::path& p : stale.changed) {
    std::printf("left %s: no job makes it now, but it changed since matbake wrote it\n", p.c_str());
  }
  for (const std::string& entry : stale.refused) {
    std::cerr << "matbake: warning: made.json lists " << escape_control(entry) << "; not removed (matbake removes only files it provably made)\n";
  }
}

// The page --report (or the manifest's `report = true`) asks for: a relative FILE is the output
// folder's; "" when none is asked. A build tool's `--only JOB` runs (Ninja's edges, Slurm's tasks)
// see one job each: the manifest's key writes no page there (`build --report` afterwards does).
fs::path report_page(const BuildSettings& s, const pipeline::Manifest& manifest) {
  if (s.report.empty() && (!manifest.report || !s.only.empty())) return {};
  const fs::path file = s.report.empty() ? fs::path("report.html") : fs::path(s.report);
  return (file.is_absolute() ? file : manifest.output / file).lexically_normal();
}

void add_output_dir_option(CLI::App& cmd, std::string& output_dir) {
  cmd.add_option("--output-dir", output_dir,
                 "Write the outputs here instead of the manifest's `output` (e.g. inside a build tree)");
}

// `build --status`: each job that is not up to date, with why; the counts; exit 1 when any failed.
// ", textures: 10 encoded, 5 from the encode cache" for a scene that made textures (KTX2, or resized
// PNG or WebP), else "".
std::string texture_counts(const nlohmann::json& details) {
  if (!details.is_object() || !details.contains("textures")) return "";
  int encoded = 0, reused = 0;
  for (const nlohmann::json& t : details["textures"]) {
    if (t.contains("reused")) ++(t["reused"].get<bool>() ? reused : encoded);
  }
  if (encoded + reused == 0) return "";
  return ", textures: " + std::to_string(encoded) + " encoded, " + std::to_string(reused) + " from the encode cache";
}

int run_status(const BuildSettings& s, const GlobalOptions& global, const pipeline::Manifest& manifest,
               const pipeline::Plan& plan) {
  auto statuses = pipeline::job_statuses(manifest, plan);
  if (!statuses) return report_error(statuses.error(), key_mention);
  std::map<pipeline::JobState, std::size_t> count;
  for (const pipeline::JobStatus& st : *statuses) {
    ++count[st.state];
    if (st.state == pipeline::JobState::failed) {
      std::cerr << "matbake: error: " << escape_control(st.detail) << " (" << st.job->name << ")\n";
    } else if (st.state == pipeline::JobState::not_built && !global.json && !global.quiet) {
      std::printf("not built %s: %s\n", st.job->name.c_str(), escape_control(st.detail).c_str());
    }
  }
  const std::size_t failed = count[pipeline::JobState::failed];
  if (global.json) {
    nlohmann::json doc = {{"command", "build"}};
    doc.update(pipeline::status_json(manifest, *statuses));
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet) {
    std::printf("up to date %zu, failed %zu, not built %zu\n", count[pipeline::JobState::up_to_date], failed,
                count[pipeline::JobState::not_built]);
  }
  if (failed) std::cerr << "matbake: error: " << s.manifest << ": " << failed << " of " << statuses->size() << " jobs failed\n";
  return failed ? kFailed : kOk;
}

// The out-of-date jobs as a Slurm submission in s.output (or, with --dry-run, its sbatch commands).
int run_slurm_plan(const PlanSettings& s, const GlobalOptions& global, pipeline::Manifest& manifest,
                   const pipeline::Plan& plan, const fs::path& self) {
  params::copy_given(pipeline::cluster_params(), s.cluster, s.cluster_given, manifest.cluster);
  if (global.jobs > 0) manifest.cluster.cpus = global.jobs;
  pipeline::RunOptions dry;
  dry.dry_run = true;
  auto report = pipeline::run(manifest, plan, dry);
  if (!report) return report_error(report.error(), key_mention);
  const auto submission = pipeline::slurm_submission(
      plan, *report, manifest.cluster,
      [&](const pipeline::Job& job) { return pipeline::job_footprint(job, manifest, int(manifest.cluster.cpus)); });
  const pipeline::SlurmTarget target{fs::absolute(s.output).lexically_normal(), self};
  auto lines = pipeline::sbatch_lines(submission, manifest.cluster, target);
  auto scripts = pipeline::slurm_scripts(manifest, submission, manifest.cluster, target);
  if (!lines || !scripts) return report_error(!lines ? lines.error() : scripts.error(), key_mention);
  if (s.dry_run) {
    if (!global.json) {
      for (const std::string& line : *lines) std::printf("%s\n", line.c_str());
      if (lines->empty()) std::printf("nothing to submit: %s\n", pipeline::submission_counts(submission).c_str());
    }
  } else if (Status st = pipeline::write_slurm_scripts(manifest, plan, *scripts, target.folder); !st) {
    return report_error(st.error(), key_mention);
  }
  if (global.json) {
    nlohmann::json doc = {{"command", "plan"}};
    doc.update(pipeline::slurm_json(submission, manifest.cluster, target, s.dry_run, *lines));
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet && !s.dry_run) {
    std::printf("%s: %s\n", (target.folder / "submit.sh").c_str(), pipeline::submission_counts(submission).c_str());
  }
  for (const std::string& w : plan.warnings) std::cerr << "matbake: warning: " << escape_control(w) << "\n";
  return kOk;
}

}  // namespace

CLI::App* setup_build(CLI::App& app, BuildSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "build",
      "Build a manifest's materials and scenes (docs/build.md): sources are decoded, converted to the layout's\n"
      "workflow, packed, validated; scenes are exported with them and AO. Only out-of-date outputs are built.");
  cmd->add_option("manifest", s.manifest, "The manifest (TOML)")->required();
  add_output_dir_option(*cmd, s.output_dir);
  CLI::Option* force = cmd->add_flag("--force", s.force, "Build every job, up to date or not");
  CLI::Option* dry_run = cmd->add_flag("-n,--dry-run", s.dry_run, "List what would be built, and why, without building it");
  CLI::Option* keep_stale = cmd->add_flag("--keep-stale", s.keep_stale,
                "Keep the files an earlier build made that no job makes now (by default a full run with no failure removes them)");
  CLI::Option* prune = cmd->add_flag("--prune", s.prune,
                "Allow what a lost input looks like: removing more than half of the files the build made, or a scene\n"
                "losing a manifest material it was built with (without it, the files are kept and the scene refused)");
  CLI::Option* status = cmd->add_flag("--status", s.status,
                "Build nothing; say how each job stands after runs elsewhere (a cluster, docs/cluster.md): up to date,\n"
                "failed (its error line) or not built. Exit 1 when any failed");
  CLI::Option* only = cmd->add_option("--only", s.only, "Build only this job (material:NAME or scene:NAME); repeatable");
  CLI::Option* depfile = cmd->add_option("--depfile", s.depfile,
                  "Write a Make depfile of every input read, for CMake add_custom_command(DEPFILE) and Ninja");
  CLI::Option* stamp = cmd->add_option("--stamp", s.stamp,
                  "Write this file after a successful run; the depfile's target is then this file rather than the outputs");
  CLI::Option* report = cmd->add_flag("--report{report.html}", s.report,
                "Write one HTML page of the build (--report=FILE: that file, inside the output folder; default\n"
                "OUT/report.html; also `report = true` in the manifest): every job, each material's textures and\n"
                "checks, each scene's AO and delivered textures (docs/build.md#the-report-page)");
  // --status builds nothing: a flag about building beside it would be silently ignored.
  for (CLI::Option* building : {force, dry_run, keep_stale, prune, only, depfile, stamp, report}) status->excludes(building);
  report->excludes(only);  // the page is the whole build's; an --only run knows one job
  return cmd;
}

CLI::App* setup_plan(CLI::App& app, PlanSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "Hand a manifest's jobs to a scheduler: a Ninja file with one edge per job (Ninja re-runs what changed), or\n"
      "a Slurm submission of the out-of-date jobs (docs/cluster.md)");
  cmd->add_option("manifest", s.manifest, "The manifest (TOML)")->required();
  cmd->add_option("-o,--output", s.output,
                  "ninja: the Ninja file to write (e.g. build.ninja); slurm: the folder of submit.sh, job.sh and logs/")
      ->required();
  cmd->add_option("--format", s.format, "ninja, or slurm (a job array of the materials, each scene after its own)")
      ->check(CLI::IsMember({"ninja", "slurm"}))
      ->capture_default_str();
  cmd->add_option("--matbake", s.matbake, "The matbake the jobs run (default: this one)");
  cmd->add_flag("-n,--dry-run", s.dry_run, "slurm: print the sbatch commands the submission would run; write nothing");
  add_output_dir_option(*cmd, s.output_dir);
  add_params(*cmd, pipeline::cluster_params(), s.cluster, "", "Slurm (--format slurm; also the manifest's [cluster])",
             &s.cluster_given);
  return cmd;
}

int run_plan(const PlanSettings& s, const GlobalOptions& global) {
  pipeline::Manifest manifest;
  auto plan = load(s.manifest, s.output_dir, global, manifest);
  if (!plan) return report_error(plan.error(), key_mention);
  std::error_code ec;
  const fs::path self = s.matbake.empty() ? fs::read_symlink("/proc/self/exe", ec) : fs::absolute(s.matbake);
  if (s.format == "slurm") return run_slurm_plan(s, global, manifest, *plan, self);
  const NamedOutput ninja_file[] = {{fs::absolute(s.output).lexically_normal(), "-o"}};
  if (Status st = pipeline::check_side_outputs(manifest, *plan, ninja_file); !st) return report_error(st.error(), key_mention);
  auto text = pipeline::ninja_text(manifest, *plan, self, ninja_file[0].path);
  if (!text) return report_error(text.error(), key_mention);
  if (Status st = write_file_atomically(ninja_file[0].path, *text); !st) return report_error(st.error(), key_mention);
  if (global.json) {
    nlohmann::json jobs = nlohmann::json::array();
    for (const pipeline::Job& j : plan->jobs) jobs.push_back(j.name);
    std::cout << nlohmann::json{{"command", "plan"}, {"ninja_file", s.output}, {"jobs", jobs}}.dump(2) << "\n";
  } else if (!global.quiet) {
    std::printf("%s: %zu edges\n", s.output.c_str(), plan->jobs.size());
  }
  for (const std::string& w : plan->warnings) std::cerr << "matbake: warning: " << escape_control(w) << "\n";
  return kOk;
}

int run_build(const BuildSettings& s, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  pipeline::Manifest manifest;
  auto plan = load(s.manifest, s.output_dir, global, manifest);
  if (!plan) return report_error(plan.error(), key_mention);
  if (s.status) return run_status(s, global, manifest, *plan);
  const NamedOutput side_outputs[] = {{s.depfile, "--depfile"}, {s.stamp, "--stamp"}};
  if (Status st = pipeline::check_side_outputs(manifest, *plan, side_outputs); !st) return report_error(st.error(), key_mention);
  if (!s.depfile.empty()) {
    if (Status st = pipeline::check_depfile_paths(manifest, *plan); !st) return report_error(st.error(), key_mention);
  }
  const fs::path page = s.dry_run ? fs::path() : report_page(s, manifest);
  if (!page.empty()) {
    if (Status st = pipeline::check_report_page(manifest, *plan, page); !st) return report_error(st.error(), key_mention);
  }
  if (!global.quiet) {
    for (const std::string& w : plan->warnings) std::cerr << "matbake: warning: " << escape_control(w) << "\n";
  }

  // Progress: a bar on a terminal; elsewhere (build logs) a line per job started and finished, and
  // one at least every 10 s while one runs.
  const bool terminal = isatty(STDERR_FILENO) != 0;
  SilencedStderr quiet;  // the image libraries' own messages: each job's error line says it
  pipeline::BuildProgress tracker;
  using Mode = ProgressBar::Mode;
  ProgressBar bar(tracker, global.quiet || s.dry_run ? Mode::quiet : terminal ? Mode::terminal : Mode::log, quiet.original_fd());
  pipeline::RunOptions options;
  options.tracker = &tracker;
  options.force = s.force;
  options.dry_run = s.dry_run;
  options.only = s.only;
  options.keep_stale = s.keep_stale;
  options.prune = s.prune;
  options.progress = [&](const pipeline::JobReport& r, std::size_t done, std::size_t total) {
    if (r.outcome == pipeline::Outcome::failed) {
      bar.print_above("matbake: error: " + job_error(r));
    } else if (r.outcome == pipeline::Outcome::skipped) {
      bar.print_above("matbake: " + r.job->name + " skipped: " + r.reason);
    } else if (!global.quiet && !terminal) {
      char line[64];
      std::snprintf(line, sizeof line, "[%zu/%zu] ", done, total);
      bar.print_above(line + r.job->name + " built (" + std::to_string(int(r.seconds * 1000)) + " ms" + texture_counts(r.details) + ")");
    }
  };
  auto report = pipeline::run(manifest, *plan, options);
  bar.finish();
  quiet.restore();
  if (!report) return report_error(report.error(), key_mention);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t failed = report->count(pipeline::Outcome::failed);

  if (!s.dry_run) {
    if (Status st = pipeline::write_build_tool_files(manifest, *report, s.depfile, s.stamp); !st) {
      return report_error(st.error(), key_mention);
    }
    if (!page.empty()) {
      if (Status st = pipeline::write_report_page(manifest, *plan, *report, page); !st) return report_error(st.error(), key_mention);
      if (!global.json && !global.quiet) std::printf("report: %s\n", page.c_str());
    }
  }
  if (global.json) {
    nlohmann::json doc = {{"command", "build"}, {"dry_run", s.dry_run}, {"seconds", seconds}};
    doc.update(pipeline::json_report(manifest, *plan, *report));
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet) {
    if (s.dry_run) {
      for (const pipeline::MaterialRule& rule : manifest.rules) {
        std::printf("material_rules.%s (%s): %zu materials: %s\n", rule.name.c_str(), rule.origin.c_str(),
                    rule.materials.size(), join(rule.materials, ", ").c_str());
      }
      for (const pipeline::JobReport& r : report->jobs) {
        if (r.outcome == pipeline::Outcome::out_of_date) std::printf("would build %s: %s\n", r.job->name.c_str(), r.reason.c_str());
      }
    }
  }
  if (s.dry_run) {  // a run reports each failure as it happens (progress above)
    for (const pipeline::JobReport& r : report->jobs) {
      if (r.outcome == pipeline::Outcome::failed) std::cerr << "matbake: error: " << job_error(r) << "\n";
    }
  }
  if (!global.json && !global.quiet) {
    for (const pipeline::JobReport& r : report->jobs) {
      for (const std::string& w : r.warnings) std::cerr << "matbake: warning: " << escape_control(r.job->name + ": " + w) << "\n";
    }
    print_stale(report->stale, s.dry_run);
    for (const std::string& w : report->warnings) std::cerr << "matbake: warning: " << escape_control(w) << "\n";
    const std::size_t built = report->count(pipeline::Outcome::built), current = report->count(pipeline::Outcome::up_to_date),
                      pending = report->count(pipeline::Outcome::out_of_date), skipped = report->count(pipeline::Outcome::skipped);
    if (built + failed + pending + skipped == 0) {
      std::printf("nothing to do: %zu jobs up to date\n", current);
    } else if (s.dry_run) {
      std::printf("%zu of %zu jobs would be built\n", pending, report->jobs.size());
    } else {
      std::string also = skipped ? ", skipped " + std::to_string(skipped) : "";
      std::size_t gated = 0;  // those over the limit with validate.gate on: among the failed
      for (const pipeline::JobReport& r : report->jobs) {
        const nlohmann::json& v = r.details.is_object() ? r.details.value("validation", nlohmann::json()) : nlohmann::json();
        gated += v.is_object() && !v.value("passed", true) && v.value("gate", false);
      }
      if (gated) also += "; " + std::to_string(gated) + " failed validation";
      if (const std::size_t over = report->over_validation_limit() - gated) {
        also += "; " + std::to_string(over) + " over their validation limit (advisory: validate.gate is off)";
      }
      std::printf("built %zu, up to date %zu, failed %zu%s; %zu images decoded; %.2f s\n", built, current, failed,
                  also.c_str(), report->images_decoded, seconds);
    }
  }
  for (const pipeline::JobReport& r : report->jobs) {
    for (const fs::path& p : r.moved) {
      report_error(Error{p.string(), "changed while " + r.job->name +
                                         " read it; its outputs are from the earlier bytes (as its stamp records): build again"});
    }
  }
  if (!report->stale.held_back.empty()) std::cerr << "matbake: error: " << s.manifest << ": " << spell_mentions(report->stale.held_back, key_mention) << "\n";
  if (failed) {
    std::cerr << "matbake: error: " << s.manifest << ": " << failed << " of " << report->jobs.size() << " jobs failed\n";
    return kFailed;
  }
  if (!report->stale.held_back.empty()) return kFailed;
  return report->moved() ? kFailed : kOk;
}

}  // namespace matbake::cli
