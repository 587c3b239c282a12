#include "interrupt.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <thread>

#include "matbake/atomic_file.hpp"
#include "matbake/subprocess.hpp"

namespace matbake::cli {

void remove_temporary_files_on_interrupt() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGHUP);
  if (pthread_sigmask(SIG_BLOCK, &signals, nullptr) != 0) return;
  // stderr may be silenced when the signal comes; close-on-exec, so no program we start holds it.
  const int message_fd = ::fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 0);
  std::thread([signals, message_fd] {
    int signal = 0;
    if (sigwait(&signals, &signal) != 0) return;
    kill_subprocesses_for_exit();  // first: an encoder may be writing into a temporary folder
    remove_temporary_files_for_exit();
    static constexpr char kMessage[] = "\nmatbake: interrupted: finished outputs kept, partial ones removed\n";
    if (message_fd >= 0) (void)!::write(message_fd, kMessage, sizeof kMessage - 1);
    ::_exit(128 + signal);
  }).detach();
}

}  // namespace matbake::cli
