#include <map>

#include "matbake/pipeline.hpp"
#include "state.hpp"

namespace matbake::pipeline {

Result<std::vector<JobStatus>> job_statuses(const Manifest& manifest, const Plan& plan) {
  RunOptions dry;
  dry.dry_run = true;
  auto report = run(manifest, plan, dry);
  if (!report) return report.error();
  const StampRoots roots{plan.state_folder, manifest.folder, manifest.output};
  std::vector<JobStatus> statuses;
  std::map<std::string, JobState> state_of;
  for (const JobReport& r : report->jobs) {  // plan order: a scene after its materials
    JobStatus s{r.job, JobState::up_to_date, {}};
    if (r.outcome != Outcome::up_to_date) {
      const std::optional<std::string> failure = recorded_failure(r.job->name, roots);
      s.state = failure ? JobState::failed : JobState::not_built;
      s.detail = failure ? *failure : r.error ? r.error->to_string() : r.reason;
      for (const std::string& name : r.job->depends_on) {
        if (!failure && state_of[name] == JobState::failed) s.detail = "waits for " + name + ", which failed";
      }
    }
    state_of[r.job->name] = s.state;
    statuses.push_back(std::move(s));
  }
  return statuses;
}

nlohmann::json status_json(const Manifest& manifest, const std::vector<JobStatus>& statuses) {
  nlohmann::json jobs = nlohmann::json::array(), counts = nlohmann::json::object();
  for (const auto& [state, name] : kJobStateNames) counts[std::string(name)] = 0;
  for (const JobStatus& st : statuses) {
    const std::string state(name_in(kJobStateNames, st.state));
    jobs.push_back({{"name", st.job->name}, {"state", state}, {"detail", st.detail}});
    counts[state] = counts[state].get<int>() + 1;
  }
  return {{"status", true}, {"manifest", manifest.file}, {"jobs", jobs}, {"counts", counts}};
}

}  // namespace matbake::pipeline
