#include "progress_bar.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

namespace matbake::cli {
namespace {

constexpr auto kRedraw = std::chrono::milliseconds(250);
constexpr auto kQuickRun = std::chrono::milliseconds(500);  // a run this quick shows no bar
constexpr auto kLogInterval = std::chrono::seconds(10);     // a running job's line in a log, at least this often

std::size_t terminal_width(int fd) {
  winsize size{};
  if (ioctl(fd, TIOCGWINSZ, &size) == 0 && size.ws_col > 20) return size.ws_col - 1;
  return 79;
}

}  // namespace

ProgressBar::ProgressBar(pipeline::BuildProgress& tracker, Mode mode, int fd)
    : tracker_(tracker), mode_(mode), fd_(fd) {
  if (mode_ != Mode::quiet) thread_ = std::thread([this] { loop(); });
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::write_text(const std::string& text) const {
  for (std::size_t at = 0; at < text.size();) {
    const ssize_t n = ::write(fd_, text.data() + at, text.size() - at);
    if (n <= 0) return;
    at += std::size_t(n);
  }
}

void ProgressBar::loop() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    tick(pipeline::BuildProgress::Clock::now());
    wake_.wait_for(lock, kRedraw);
  }
}

void ProgressBar::tick(pipeline::BuildProgress::Clock::time_point now) {
  if (mode_ == Mode::log) {
    for (const std::string& line : tracker_.log_lines(now, kLogInterval)) write_text(line + "\n");
  } else if (mode_ == Mode::terminal && now - start_ >= kQuickRun) {
    last_ = "\r\033[K" + tracker_.status_line(now, terminal_width(fd_));
    drawn_ = true;
    write_text(last_);
  }
}

void ProgressBar::print_above(const std::string& line) {
  std::lock_guard lock(mutex_);
  if (mode_ == Mode::log) tick(pipeline::BuildProgress::Clock::now());  // a job's start line before its end
  if (drawn_) write_text("\r\033[K");
  write_text(line + "\n");
  if (drawn_) write_text(last_);
}

void ProgressBar::finish() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    if (mode_ == Mode::log) tick(pipeline::BuildProgress::Clock::now());
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (drawn_) write_text("\r\033[K");
  drawn_ = false;
}

}  // namespace matbake::cli
