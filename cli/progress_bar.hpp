#pragma once
// A build's progress on stderr (docs/build.md "Progress"), drawn by its own thread from a
// pipeline::BuildProgress: on a terminal one line redrawn in place (bar, share of work, ETA, the
// running jobs and their stage), shown once the run has taken half a second; in a log, a line when a
// job starts and one at least every 10 s while it runs. Messages are printed above either.
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "matbake/build_progress.hpp"

namespace matbake::cli {

class ProgressBar {
 public:
  enum class Mode { terminal, log, quiet };
  // `fd`: where to write (stderr, or its saved copy while fd 2 is silenced).
  ProgressBar(pipeline::BuildProgress& tracker, Mode mode, int fd);
  ~ProgressBar();
  void print_above(const std::string& line);  // one line, kept in the scrollback
  void finish();                               // stops drawing, clears the bar

 private:
  void loop();
  void tick(pipeline::BuildProgress::Clock::time_point now);  // under mutex_
  void write_text(const std::string& text) const;

  pipeline::BuildProgress& tracker_;
  Mode mode_;
  int fd_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool drawn_ = false;
  std::string last_;
  pipeline::BuildProgress::Clock::time_point start_ = pipeline::BuildProgress::Clock::now();
  std::thread thread_;  // last: started once the rest is set
};

}  // namespace matbake::cli
