// What a build leaves behind besides its outputs: the --json report and the build tool's files.
#include <algorithm>

#include "matbake/atomic_file.hpp"
#include "matbake/pipeline.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

std::vector<std::string> strings(const std::vector<fs::path>& paths) {
  return {paths.begin(), paths.end()};
}

nlohmann::json job_json(const JobReport& r) {
  nlohmann::json j = {{"name", r.job->name},
                      {"outcome", name_in(kOutcomeNames, r.outcome)},
                      {"inputs", strings(r.job->inputs)},
                      {"outputs", strings(r.job->outputs.all())},
                      {"seconds", r.seconds},
                      {"warnings", r.warnings}};
  if (!r.reason.empty()) j["reason"] = r.reason;
  if (!r.changed.is_null()) j["changed"] = r.changed;
  if (!r.job->depends_on.empty()) j["depends_on"] = r.job->depends_on;
  if (!r.moved.empty()) j["moved"] = strings(r.moved);
  if (r.error) j["error"] = r.error->to_string();
  if (!r.details.is_null()) j["details"] = r.details;
  return j;
}

}  // namespace

nlohmann::json json_report(const Manifest& manifest, const Plan& plan, const Report& report) {
  nlohmann::json jobs = nlohmann::json::array();
  for (const JobReport& r : report.jobs) jobs.push_back(job_json(r));
  nlohmann::json rules = nlohmann::json::array();
  for (const MaterialRule& rule : manifest.rules) {
    rules.push_back({{"name", rule.name}, {"origin", rule.origin}, {"materials", rule.materials}});
  }
  nlohmann::json j = {{"manifest", manifest.file.string()},
                      {"material_rules", rules},
                      {"output", manifest.output.string()},
                      {"jobs", jobs},
                      {"images_decoded", report.images_decoded},
                      {"stale", {{"removed", strings(report.stale.removed)},
                                 {"kept", strings(report.stale.kept)},
                                 {"changed", strings(report.stale.changed)},
                                 {"refused", report.stale.refused}}},
                      {"warnings", plan.warnings}};
  for (const std::string& w : report.warnings) j["warnings"].push_back(w);
  for (const auto& [outcome, name] : kOutcomeNames) j[std::string(name)] = report.count(outcome);
  j["over_validation_limit"] = report.over_validation_limit();
  return j;
}

Status write_build_tool_files(const Manifest& manifest, const Report& report, const fs::path& depfile,
                              const fs::path& stamp) {
  if (!depfile.empty()) {
    std::vector<fs::path> targets, inputs = {manifest.file};
    for (const JobReport& r : report.jobs) {
      const std::vector<fs::path> files = r.job->outputs.all();
      targets.insert(targets.end(), files.begin(), files.end());
      for (const fs::path& p : r.job->inputs) {
        if (std::find(inputs.begin(), inputs.end(), p) == inputs.end()) inputs.push_back(p);
      }
    }
    // The folders material rules scan too: a new texture set there is a new material (CMake and
    // Ninja compare a folder's time like a file's).
    for (const MaterialRule& rule : manifest.rules) {
      if (std::find(inputs.begin(), inputs.end(), rule.folder) == inputs.end()) inputs.push_back(rule.folder);
    }
    if (!stamp.empty()) targets = {fs::absolute(stamp).lexically_normal()};
    auto text = depfile_text(targets, inputs);
    if (!text) return text.error();
    if (Status s = write_file_atomically(depfile, *text); !s) return s;
  }
  if (!stamp.empty() && report.count(Outcome::failed) == 0 && report.moved() == 0) {
    const std::string text = "matbake build " + manifest.file.string() + ": " + std::to_string(report.jobs.size()) + " jobs\n";
    if (Status s = write_file_atomically(stamp, text); !s) return s;
  }
  return success();
}

}  // namespace matbake::pipeline
