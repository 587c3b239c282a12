// A build's progress: running jobs, their stage, the share of work done and the time left.
#include <algorithm>
#include <cstdio>

#include "matbake/build_progress.hpp"

namespace matbake::pipeline {
namespace {

std::string minutes_seconds(double seconds) {
  const long s = long(std::max(0.0, seconds) + 0.5);
  char text[32];
  if (s >= 3600) {
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%ld:%02ld", s / 60, s % 60);
  }
  return text;
}

double seconds_between(BuildProgress::Clock::time_point from, BuildProgress::Clock::time_point to) {
  return std::chrono::duration<double>(to - from).count();
}

}  // namespace

double JobWork::done_at(Phase phase, double fraction) const {
  const double parts[] = {read, ao, textures, write};
  const int at = int(phase);
  double done = 0;
  for (int i = 0; i < at; ++i) done += parts[i];
  return done + parts[at] * std::clamp(fraction, 0.0, 1.0);
}

void BuildProgress::planned(const std::vector<std::pair<const Job*, JobWork>>& jobs, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  start_ = now;
  for (const auto& [job, work] : jobs) {
    planned_[job] = work;
    total_ += work.total();
  }
}

void BuildProgress::started(const Job& job, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  ++jobs_started_;
  const auto found = planned_.find(&job);
  running_.push_back({&job, found == planned_.end() ? JobWork{} : found->second, now, now});
  starts_.push_back(job.name + " started (" + std::to_string(jobs_started_) + " of " + std::to_string(planned_.size()) + ")");
}

void BuildProgress::stage(const Job& job, Phase phase, std::string_view what, double fraction) {
  std::lock_guard lock(mutex_);
  for (Running& r : running_) {
    if (r.job != &job) continue;
    r.phase = phase;
    r.what = std::string(what);
    r.fraction = fraction;
  }
}

void BuildProgress::finished(const Job& job) {
  std::lock_guard lock(mutex_);
  const auto found = planned_.find(&job);
  if (found != planned_.end()) finished_work_ += found->second.total();
  ++jobs_finished_;
  std::erase_if(running_, [&](const Running& r) { return r.job == &job; });
}

double BuildProgress::done_locked() const {
  if (total_ <= 0) return jobs_started_ ? double(jobs_finished_) / double(jobs_started_) : 0;
  double done = finished_work_;
  for (const Running& r : running_) done += r.work.done_at(r.phase, r.fraction);
  return std::clamp(done / total_, 0.0, 1.0);
}

double BuildProgress::fraction_done() const {
  std::lock_guard lock(mutex_);
  return done_locked();
}

std::optional<double> BuildProgress::left_locked(Clock::time_point now) const {
  const double done = done_locked();
  if (done <= 0) return std::nullopt;
  return seconds_between(start_, now) * (1 - done) / done;
}

std::optional<double> BuildProgress::seconds_left(Clock::time_point now) const {
  std::lock_guard lock(mutex_);
  return left_locked(now);
}

std::string BuildProgress::running_text(const Running& r, Clock::time_point now) const {
  return r.job->name + " (" + r.what + ", " + std::to_string(long(seconds_between(r.start, now))) + " s)";
}

std::string BuildProgress::status_line(Clock::time_point now, std::size_t width) const {
  std::lock_guard lock(mutex_);
  const double done = done_locked();
  const std::optional<double> left = left_locked(now);
  constexpr int kBar = 20;
  std::string bar(std::size_t(done * kBar), '#');
  bar.resize(kBar, '.');
  char head[96];
  std::snprintf(head, sizeof head, "[%s] %zu/%zu %3d%% %s", bar.c_str(), jobs_finished_, planned_.size(), int(done * 100),
                left ? ("ETA " + minutes_seconds(*left)).c_str() : "ETA -:--");
  std::string line = head;
  for (std::size_t i = 0; i < running_.size(); ++i) line += (i ? ", " : "  ") + running_text(running_[i], now);
  if (line.size() > width && width > 3) line = line.substr(0, width - 3) + "...";
  return line;
}

std::vector<std::string> BuildProgress::log_lines(Clock::time_point now, Clock::duration interval) {
  std::lock_guard lock(mutex_);
  std::vector<std::string> lines = std::move(starts_);
  starts_.clear();
  for (Running& r : running_) {
    if (now - r.said < interval) continue;
    r.said = now;
    const std::optional<double> left = left_locked(now);
    lines.push_back(r.job->name + " running: " + r.what + ", " + std::to_string(long(seconds_between(r.start, now))) + " s" +
                    (left ? "; build " + std::to_string(int(done_locked() * 100)) + "% done, ETA " + minutes_seconds(*left) : ""));
  }
  return lines;
}

}  // namespace matbake::pipeline
