#pragma once
// Progress of a long run on stderr: on a terminal, one line redrawn in place (done / total, a bar,
// the ETA), shown only once the run has taken more than half a second; messages printed above it.
#include <chrono>
#include <string>

namespace matbake::cli {

class ProgressBar {
 public:
  // `fd`: where to write (stderr, or its saved copy while fd 2 is silenced). `enabled`: draw the bar
  // (a terminal, not --quiet); messages are printed either way.
  ProgressBar(bool enabled, int fd);
  void update(std::size_t done, std::size_t total);
  void print_above(const std::string& line);  // one line, kept in the scrollback
  void finish();                               // clears the bar

 private:
  void write_text(const std::string& text) const;
  bool enabled_;
  int fd_;
  bool drawn_ = false;
  std::string last_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace matbake::cli
