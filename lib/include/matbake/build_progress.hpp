#pragma once
// A build's progress as a display shows it (docs/build.md "Progress"): the running jobs with their
// stage, the share of the build's work done (each job weighted by its modelled work: texels
// decoded and written, rays traced, textures encoded) and the time left at that pace; and for a
// log, a line when a job starts and one at least every interval while it runs.
#include <chrono>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "matbake/pipeline.hpp"
#include "matbake/stage.hpp"

namespace matbake::pipeline {

// A job's work by phase, in modelled seconds on the 2-core reference machine (rates in
// job_memory.cpp); only their ratios matter, the ETA scales them by the run's own pace.
struct JobWork {
  double read = 0, ao = 0, textures = 0, write = 0;
  double total() const { return read + ao + textures + write; }
  // The work done once `phase` is `fraction` done (the phases before it complete).
  double done_at(Phase phase, double fraction) const;
};
JobWork job_work(const Job& job, const Manifest& manifest);

class BuildProgress {
 public:
  using Clock = std::chrono::steady_clock;

  // The jobs the run will run, with their work, before the first starts.
  void planned(const std::vector<std::pair<const Job*, JobWork>>& jobs, Clock::time_point now);
  void started(const Job& job, Clock::time_point now);
  void stage(const Job& job, Phase phase, std::string_view what, double fraction);
  void finished(const Job& job);

  // Of the planned work, done (finished jobs, and running ones by their phase), 0 to 1.
  double fraction_done() const;
  // The time left at the pace so far; none before any work is done.
  std::optional<double> seconds_left(Clock::time_point now) const;
  // One terminal line of at most `width` characters: bar, jobs done, share, ETA, running jobs.
  std::string status_line(Clock::time_point now, std::size_t width) const;
  // For a log: "started" for each job started since the last call (also of jobs done since), and for
  // each running job not mentioned for `interval`, where it is. Each line is then counted as said.
  std::vector<std::string> log_lines(Clock::time_point now, Clock::duration interval);

 private:
  struct Running {
    const Job* job = nullptr;
    JobWork work;
    Clock::time_point start, said;
    std::string what = "starting";
    Phase phase = Phase::read;
    double fraction = 0;
  };
  double done_locked() const;
  std::optional<double> left_locked(Clock::time_point now) const;
  std::string running_text(const Running& r, Clock::time_point now) const;

  mutable std::mutex mutex_;
  std::map<const Job*, JobWork> planned_;
  std::vector<Running> running_;  // in the order they started
  std::vector<std::string> starts_;  // "started" lines not yet taken by log_lines
  double total_ = 0, finished_work_ = 0;
  std::size_t jobs_finished_ = 0, jobs_started_ = 0;
  Clock::time_point start_{};
};

}  // namespace matbake::pipeline
