#include <unistd.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>

#include "commands.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/pipeline.hpp"
#include "progress_bar.hpp"
#include "silenced_stderr.hpp"

namespace matbake::cli {
namespace fs = std::filesystem;
namespace {

std::string job_error(const pipeline::JobReport& r) { return r.error->to_string() + " (" + r.job->name + ")"; }

Result<pipeline::Plan> load(const std::string& manifest_file, const std::string& output_dir, pipeline::Manifest& manifest) {
  auto m = pipeline::read_manifest(manifest_file);
  if (!m) return m.error();
  manifest = std::move(*m);
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
}

void add_output_dir_option(CLI::App& cmd, std::string& output_dir) {
  cmd.add_option("--output-dir", output_dir,
                 "Write the outputs here instead of the manifest's `output` (e.g. inside a build tree)");
}

}  // namespace

CLI::App* setup_build(CLI::App& app, BuildSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "build",
      "Build a manifest's materials and scenes (docs/build.md): sources are decoded, converted to the layout's\n"
      "workflow, packed, validated; scenes are exported with them and AO. Only out-of-date outputs are built.");
  cmd->add_option("manifest", s.manifest, "The manifest (TOML)")->required();
  add_output_dir_option(*cmd, s.output_dir);
  cmd->add_flag("--force", s.force, "Build every job, up to date or not");
  cmd->add_flag("-n,--dry-run", s.dry_run, "List what would be built, and why, without building it");
  cmd->add_flag("--keep-stale", s.keep_stale,
                "Keep the files an earlier build made that no job makes now (by default a full run with no failure removes them)");
  cmd->add_option("--only", s.only, "Build only this job (material:NAME or scene:NAME); repeatable");
  cmd->add_option("--depfile", s.depfile,
                  "Write a Make depfile of every input read, for CMake add_custom_command(DEPFILE) and Ninja");
  cmd->add_option("--stamp", s.stamp,
                  "Write this file after a successful run; the depfile's target is then this file rather than the outputs");
  return cmd;
}

CLI::App* setup_plan(CLI::App& app, PlanSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "plan", "Write a Ninja file with one edge per job of a manifest: Ninja schedules them and re-runs what changed");
  cmd->add_option("manifest", s.manifest, "The manifest (TOML)")->required();
  cmd->add_option("-o,--output", s.output, "The Ninja file to write (e.g. build.ninja)")->required();
  cmd->add_option("--matbake", s.matbake, "The matbake the edges run (default: this one)");
  add_output_dir_option(*cmd, s.output_dir);
  return cmd;
}

int run_plan(const PlanSettings& s, const GlobalOptions& global) {
  pipeline::Manifest manifest;
  auto plan = load(s.manifest, s.output_dir, manifest);
  if (!plan) return report_error(plan.error());
  std::error_code ec;
  const fs::path self = s.matbake.empty() ? fs::read_symlink("/proc/self/exe", ec) : fs::absolute(s.matbake);
  if (Status st = write_file_atomically(s.output, pipeline::ninja_text(manifest, *plan, self, s.output)); !st) {
    return report_error(st.error());
  }
  if (global.json) {
    nlohmann::json jobs = nlohmann::json::array();
    for (const pipeline::Job& j : plan->jobs) jobs.push_back(j.name);
    std::cout << nlohmann::json{{"command", "plan"}, {"ninja_file", s.output}, {"jobs", jobs}}.dump(2) << "\n";
  } else if (!global.quiet) {
    std::printf("%s: %zu edges\n", s.output.c_str(), plan->jobs.size());
  }
  for (const std::string& w : plan->warnings) std::cerr << "matbake: warning: " << w << "\n";
  return kOk;
}

int run_build(const BuildSettings& s, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  pipeline::Manifest manifest;
  auto plan = load(s.manifest, s.output_dir, manifest);
  if (!plan) return report_error(plan.error());
  if (!global.quiet) {
    for (const std::string& w : plan->warnings) std::cerr << "matbake: warning: " << w << "\n";
  }

  // Progress: a bar on a terminal; elsewhere (build logs) one line per finished job.
  const bool terminal = isatty(STDERR_FILENO) != 0;
  std::optional<SilencedStderr> quiet(std::in_place);  // the image libraries' own messages: each job's error line says it
  ProgressBar bar(terminal && !global.quiet, quiet->original_fd());
  pipeline::RunOptions options;
  options.force = s.force;
  options.dry_run = s.dry_run;
  options.only = s.only;
  options.keep_stale = s.keep_stale;
  options.progress = [&](const pipeline::JobReport& r, std::size_t done, std::size_t total) {
    if (r.outcome == pipeline::Outcome::failed) {
      bar.print_above("matbake: error: " + job_error(r));
    } else if (r.outcome == pipeline::Outcome::skipped) {
      bar.print_above("matbake: " + r.job->name + " skipped: " + r.reason);
    } else if (!global.quiet && !terminal) {
      char line[64];
      std::snprintf(line, sizeof line, "[%zu/%zu] ", done, total);
      bar.print_above(line + r.job->name + " built (" + std::to_string(int(r.seconds * 1000)) + " ms)");
    }
    bar.update(done, total);
  };
  auto report = pipeline::run(manifest, *plan, options);
  bar.finish();
  quiet.reset();
  if (!report) return report_error(report.error());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t failed = report->count(pipeline::Outcome::failed);

  if (!s.dry_run) {
    if (Status st = pipeline::write_build_tool_files(manifest, *report, s.depfile, s.stamp); !st) {
      return report_error(st.error());
    }
  }
  if (global.json) {
    nlohmann::json doc = {{"command", "build"}, {"dry_run", s.dry_run}, {"seconds", seconds}};
    doc.update(pipeline::json_report(manifest, *plan, *report));
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet) {
    if (s.dry_run) {
      for (const pipeline::MaterialRule& rule : manifest.rules) {
        std::string names;
        for (const std::string& n : rule.materials) names += (names.empty() ? "" : ", ") + n;
        std::printf("material_rules.%s (%s): %zu materials: %s\n", rule.name.c_str(), rule.origin.c_str(),
                    rule.materials.size(), names.c_str());
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
      for (const std::string& w : r.warnings) std::cerr << "matbake: warning: " << r.job->name << ": " << w << "\n";
    }
    print_stale(report->stale, s.dry_run);
    for (const std::string& w : report->warnings) std::cerr << "matbake: warning: " << w << "\n";
    const std::size_t built = report->count(pipeline::Outcome::built), current = report->count(pipeline::Outcome::up_to_date),
                      pending = report->count(pipeline::Outcome::out_of_date), skipped = report->count(pipeline::Outcome::skipped);
    if (built + failed + pending + skipped == 0) {
      std::printf("nothing to do: %zu jobs up to date\n", current);
    } else if (s.dry_run) {
      std::printf("%zu of %zu jobs would be built\n", pending, report->jobs.size());
    } else {
      std::string also = skipped ? ", skipped " + std::to_string(skipped) : "";
      if (const std::size_t over = report->over_validation_limit()) {
        also += "; " + std::to_string(over) + " over their validation limit (advisory)";
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
  if (failed) {
    std::cerr << "matbake: error: " << s.manifest << ": " << failed << " of " << report->jobs.size() << " jobs failed\n";
    return kFailed;
  }
  return report->moved() ? kFailed : kOk;
}

}  // namespace matbake::cli
