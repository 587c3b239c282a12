#include "progress_bar.hpp"

#include <unistd.h>

#include <cstdio>

namespace matbake::cli {

ProgressBar::ProgressBar(bool enabled, int fd) : enabled_(enabled), fd_(fd) {}

void ProgressBar::write_text(const std::string& text) const {
  for (std::size_t at = 0; at < text.size();) {
    const ssize_t n = ::write(fd_, text.data() + at, text.size() - at);
    if (n <= 0) return;
    at += std::size_t(n);
  }
}

void ProgressBar::update(std::size_t done, std::size_t total) {
  if (!enabled_ || total == 0) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (elapsed < 0.5 && done < total) return;  // a quick run shows no bar
  constexpr int kWidth = 30;
  const int filled = int(kWidth * done / total);
  std::string bar(std::size_t(filled), '#');
  bar.resize(kWidth, '.');
  char line[128];
  if (done > 0 && done < total) {
    const int eta = int(elapsed / double(done) * double(total - done) + 0.5);
    std::snprintf(line, sizeof line, "\r[%s] %zu/%zu  ETA %d:%02d ", bar.c_str(), done, total, eta / 60, eta % 60);
  } else {
    std::snprintf(line, sizeof line, "\r[%s] %zu/%zu  %.1f s ", bar.c_str(), done, total, elapsed);
  }
  last_ = line;
  drawn_ = true;
  write_text(last_);
}

void ProgressBar::print_above(const std::string& line) {
  if (drawn_) write_text("\r\033[K");
  write_text(line + "\n");
  if (drawn_) write_text(last_);
}

void ProgressBar::finish() {
  if (drawn_) write_text("\r\033[K");
  drawn_ = false;
}

}  // namespace matbake::cli
