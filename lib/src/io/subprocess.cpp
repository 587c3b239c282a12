#include "matbake/subprocess.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <map>

#include "matbake/result.hpp"

extern char** environ;

namespace matbake {
namespace {

// The process groups running now (their supervisor's pid), each with matbake's end of its life
// pipe, for the interrupt handler.
struct Running {
  std::mutex mutex;
  std::map<pid_t, int> groups;
  bool closed = false;
};
Running& running() {
  static Running r;
  return r;
}

// `pid`'s children (of its main thread) appended to `found` (at most `most`), from /proc.
void add_children(pid_t pid, pid_t* found, std::size_t& n, std::size_t most) {
  char path[64] = "/proc/", digits[16];
  std::size_t d = 0, at = 6;
  for (unsigned long v = static_cast<unsigned long>(pid); d == 0 || v > 0; v /= 10) digits[d++] = char('0' + v % 10);
  for (std::size_t k = 0; k < 2; ++k) {  // /proc/PID/task/PID/children
    for (std::size_t j = d; j > 0; --j) path[at++] = digits[j - 1];
    const char* part = k == 0 ? "/task/" : "/children";
    while (*part != 0) path[at++] = *part++;
  }
  path[at] = 0;
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return;
  char text[4096];
  const ssize_t got = ::read(fd, text, sizeof text);
  ::close(fd);
  long value = -1;
  for (ssize_t i = 0; i <= got; ++i) {
    if (i < got && text[i] >= '0' && text[i] <= '9') {
      value = (value < 0 ? 0 : value * 10) + (text[i] - '0');
    } else if (value > 0) {
      if (n < most) found[n++] = pid_t(value);
      value = -1;
    }
  }
}

// Kills every descendant of the supervisor, whatever process group or session it moved to (a
// wrapper under `set -m`, setsid): the supervisor is a child subreaper, so orphans come back to it
// and stay in its tree. Walked breadth-first from /proc until none is left (at most 1,024 a pass,
// 100 passes), each reaped.
void kill_descendants() {
  for (int pass = 0; pass < 100; ++pass) {
    pid_t found[1024];
    std::size_t n = 0;
    add_children(::getpid(), found, n, 1024);
    for (std::size_t k = 0; k < n; ++k) add_children(found[k], found, n, 1024);
    if (n == 0) return;
    for (std::size_t k = 0; k < n; ++k) ::kill(found[k], SIGKILL);
    while (::waitpid(-1, nullptr, WNOHANG) > 0) {
    }
    const timespec pause{0, 2000000};  // 2 ms: the killed become zombies, reaped by the next pass
    ::nanosleep(&pause, nullptr);
  }
}

// The child matbake forks: the leader of the program's process group, a child subreaper, which
// starts the program and waits for it. When matbake's end of the `life` pipe closes (matbake exited,
// was killed with SIGKILL, which no handler sees, or closed it at the time limit), it kills every
// descendant and its group, itself included: a wrapper that starts basisu without exec has its
// basisu killed too, which PR_SET_PDEATHSIG on the program alone cannot do (it is not inherited).
// When the program ends, what it left running is killed and the supervisor ends as the program did.
// Between fork and exit: async-signal-safe calls only.
[[noreturn]] void supervise(const char* program, char* const* argv, int output_fd, int life_fd, pid_t parent, const char* directory) {
  ::setpgid(0, 0);
  if (::getppid() != parent) ::_exit(127);  // matbake died before the pipe was watched
  ::prctl(PR_SET_CHILD_SUBREAPER, 1);
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT}) ::signal(s, SIG_DFL);
  // Moved past 0-3 first: either may be one of them in a process that closed its standard streams.
  const int out = ::fcntl(output_fd, F_DUPFD, 10), alive = ::fcntl(life_fd, F_DUPFD, 10);
  const int null = ::open("/dev/null", O_RDONLY);
  if (out < 0 || alive < 0 || null < 0 || ::dup2(null, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(out, 2) < 0 || ::dup2(alive, 3) < 0) {
    ::_exit(127);
  }
  // Nothing else of matbake's (a copy of its stderr kept for messages, a lock, another run's life
  // pipe): a program that outlived matbake would keep a pipe reading matbake's stderr waiting.
  ::close_range(4, ~0u, 0);
  // SIGCHLD blocked but while waiting in ppoll: the program's end wakes the wait, with no race.
  struct sigaction wake {};
  wake.sa_handler = [](int) {};
  ::sigaction(SIGCHLD, &wake, nullptr);
  sigset_t none, child;
  sigemptyset(&none);
  sigemptyset(&child);
  sigaddset(&child, SIGCHLD);
  ::sigprocmask(SIG_SETMASK, &child, nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(3);
    ::signal(SIGCHLD, SIG_DFL);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (directory != nullptr && ::chdir(directory) != 0) ::_exit(127);
    ::execve(program, argv, environ);
    ::_exit(127);
  }
  if (pid < 0) ::_exit(127);
  for (;;) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      kill_descendants();  // what it left running (a process holding the output pipe open)
      if (WIFSIGNALED(status)) {  // ended by a signal: so does the supervisor, for matbake's report
        ::signal(WTERMSIG(status), SIG_DFL);
        ::sigprocmask(SIG_SETMASK, &none, nullptr);
        ::kill(::getpid(), WTERMSIG(status));
      }
      ::_exit(WIFEXITED(status) ? WEXITSTATUS(status) : 127);
    }
    pollfd life{3, POLLIN, 0};
    if (::ppoll(&life, 1, nullptr, &none) > 0 && life.revents != 0) {  // matbake is gone, or asks it to end
      kill_descendants();
      ::kill(0, SIGKILL);
    }
  }
}

// Appends `bytes` to `tail`, keeping its last `limit` bytes.
void keep_tail(std::string& tail, const char* bytes, std::size_t n, std::size_t limit) {
  tail.append(bytes, n);
  if (tail.size() > 2 * limit) tail.erase(0, tail.size() - limit);
}

// Whether the child ended (not reaped: its group's id stays reserved until wait_for).
bool has_ended(pid_t pid) {
  siginfo_t info{};
  return ::waitid(P_PID, id_t(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid;
}

// Whether the child ends before the deadline (it may close its output and go on).
bool ended_by(pid_t pid, std::chrono::steady_clock::time_point deadline) {
  while (!has_ended(pid)) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    ::usleep(2000);
  }
  return true;
}

// What the pipe holds now, read without waiting for more (a process the child left behind may hold
// it open), until the deadline.
void drain(int fd, std::chrono::steady_clock::time_point deadline, std::string& tail, std::size_t limit) {
  char buffer[16384];
  pollfd p{fd, POLLIN, 0};
  while (std::chrono::steady_clock::now() < deadline && ::poll(&p, 1, 0) > 0 && (p.revents & POLLIN)) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0) return;
    keep_tail(tail, buffer, std::size_t(n), limit);
  }
}

// Reads the child's output until the child has ended and the pipe is drained or closed (a process
// it left behind may hold the pipe open), or the deadline passes: false then.
bool read_until_ended(int fd, pid_t pid, std::chrono::steady_clock::time_point deadline, std::string& tail, std::size_t limit) {
  char buffer[16384];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left.count(), 50)));
    if (ready < 0 && errno != EINTR) return true;
    if (ready == 0) {
      // The child may have written its last output and ended since poll gave up: read it (a basisu
      // probe lost its "Compressor v" line so under load and failed).
      if (!has_ended(pid)) continue;
      drain(fd, deadline, tail, limit);
      return true;
    }
    if (ready < 0) continue;
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN)) return ended_by(pid, deadline);  // closed: wait for its end
    if (n > 0) keep_tail(tail, buffer, std::size_t(n), limit);
  }
}

int exit_code(int status) { return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status); }

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return -1;
  }
  return exit_code(status);
}

}  // namespace

std::string SubprocessResult::error_line() const {
  std::string last, found;
  std::size_t start = 0;
  while (start < output_tail.size()) {
    std::size_t end = output_tail.find('\n', start);
    if (end == std::string::npos) end = output_tail.size();
    const std::string line = output_tail.substr(start, end - start);
    if (line.find_first_not_of(" \t\r") != std::string::npos) {
      last = line;
      if (found.empty() && (line.find("ERROR") != std::string::npos || line.find("Error") != std::string::npos)) found = line;
    }
    start = end + 1;
  }
  std::string line = escape_control(found.empty() ? last : found);
  if (line.size() > 300) line = line.substr(0, 297) + "...";
  return line;
}

SubprocessResult run_supervised(const SubprocessRequest& request) {
  SubprocessResult result;
  // A relative program is found from matbake's folder, wherever the child runs.
  std::error_code ec;
  const std::filesystem::path program =
      request.working_directory.empty() ? request.program : std::filesystem::absolute(request.program, ec);
  std::vector<std::string> argv_text{program.string()};
  argv_text.insert(argv_text.end(), request.args.begin(), request.args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  int pipe_fds[2], life[2];  // the program's output; matbake's life (its end closes when matbake goes)
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    result.start_error = std::strerror(errno);
    return result;
  }
  if (::pipe2(life, O_CLOEXEC) != 0) {
    result.start_error = std::strerror(errno);
    ::close(pipe_fds[0]);
    ::close(pipe_fds[1]);
    return result;
  }
  const pid_t parent = ::getpid();
  pid_t pid = -1;
  {
    // Under the lock: an interrupt sees either no child or a child in the set (its group made by
    // setpgid below as well as in the child, so a kill never misses it).
    std::lock_guard lock(running().mutex);
    if (!running().closed) pid = ::fork();
    if (pid == 0) {
      supervise(argv_text[0].c_str(), argv.data(), pipe_fds[1], life[0], parent,
                request.working_directory.empty() ? nullptr : request.working_directory.c_str());
    }
    if (pid > 0) {
      ::setpgid(pid, pid);
      running().groups[pid] = life[1];
    }
  }
  const int fork_errno = errno;
  ::close(pipe_fds[1]);
  ::close(life[0]);
  if (pid < 0) {
    ::close(pipe_fds[0]);
    ::close(life[1]);
    result.start_error = running().closed ? "interrupted" : std::strerror(fork_errno);
    return result;
  }
  const auto deadline = std::chrono::steady_clock::now() + request.time_limit;
  result.timed_out = !read_until_ended(pipe_fds[0], pid, deadline, result.output_tail, request.output_limit);
  ::close(pipe_fds[0]);
  // Everything goes: after a normal end the supervisor has killed what the program left; at the
  // time limit its life pipe closes and it kills the program's tree. The group is killed after a
  // grace second in any case (the leader, a zombie until reaped, keeps the group's id from being reused).
  {
    std::lock_guard lock(running().mutex);
    running().groups.erase(pid);
    ::close(life[1]);
  }
  (void)ended_by(pid, std::chrono::steady_clock::now() + std::chrono::seconds(1));
  ::kill(-pid, SIGKILL);
  result.status = wait_for(pid);
  if (result.output_tail.size() > request.output_limit) {
    result.output_tail.erase(0, result.output_tail.size() - request.output_limit);
  }
  if (result.status == 127 && result.output_tail.empty()) result.start_error = "cannot be run";
  return result;
}

void kill_subprocesses_for_exit() {
  Running& r = running();
  r.mutex.lock();  // held until the process exits: no program starts after this
  r.closed = true;
  for (const auto& [group, life] : r.groups) ::close(life);  // each supervisor kills its program's tree
  const auto grace = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  for (const auto& [group, life] : r.groups) {
    (void)ended_by(group, grace);
    ::kill(-group, SIGKILL);
  }
}

}  // namespace matbake
