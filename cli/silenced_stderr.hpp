#pragma once
// The libraries under OIIO 2.4's readers may print their own line about a bad file before OIIO
// returns the same problem as an error, which matbake then reports in its one-line form (libpng's
// "libpng error: ..." did, before matbake read PNG with libspng, which prints nothing). While a file is processed,
// the CLI points fd 2 at /dev/null and prints only after restoring it, so each problem is said
// once. MATBAKE_LIBRARY_MESSAGES=1 keeps the libraries' own messages (for debugging).
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace matbake::cli {

class SilencedStderr {
 public:
  SilencedStderr() {
    const char* keep = std::getenv("MATBAKE_LIBRARY_MESSAGES");
    if (keep != nullptr && std::strcmp(keep, "1") == 0) return;
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ < 0 || null < 0 || ::dup2(null, 2) < 0) restore();
    if (null >= 0) ::close(null);
  }
  ~SilencedStderr() { restore(); }
  // Where the CLI's own messages go meanwhile: the real stderr.
  int original_fd() const { return saved_ >= 0 ? saved_ : 2; }
  SilencedStderr(const SilencedStderr&) = delete;
  SilencedStderr& operator=(const SilencedStderr&) = delete;

  // fd 2 back to the real stderr before the scope ends (the destructor then does nothing).
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
    saved_ = -1;
  }

 private:
  int saved_ = -1;
};

}  // namespace matbake::cli
