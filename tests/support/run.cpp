#include "support/run.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "support/temp_dir.hpp"

extern char** environ;

namespace matbake::test {
namespace {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> merged_environment(const std::vector<std::string>& changes) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) env.emplace_back(*e);
  for (const std::string& change : changes) {
    const std::string name = change.substr(0, change.find('=') + 1);
    std::erase_if(env, [&](const std::string& e) { return e.rfind(name, 0) == 0; });
    if (change.size() > name.size()) env.push_back(change);
  }
  return env;
}

// /proc/PID/FILE's text (at most `limit` bytes), empty when the process has ended. read(2), not a
// stream: a process that ends meanwhile fails the read (ESRCH), not the test.
std::string proc_text(const std::string& pid, const char* file, std::size_t limit) {
  const int fd = open(("/proc/" + pid + "/" + file).c_str(), O_RDONLY);
  if (fd < 0) return {};
  std::string text(limit, '\0');
  const ssize_t got = read(fd, text.data(), text.size());
  close(fd);
  text.resize(got > 0 ? std::size_t(got) : 0);
  return text;
}

// The memory (bytes) the process tree under `root` holds: each process's proportional set size
// (a page shared by n processes counts 1/n to each, so a forked child not yet running its program
// adds nothing), summed over `root` and every descendant, whatever process group it is in (matbake
// starts its encoders in groups of their own) — as a cluster's cgroup counts a job.
double tree_memory_bytes(pid_t root) {
  std::map<long, std::vector<std::string>> children;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ec)) {
    const std::string pid = entry.path().filename().string();
    if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = proc_text(pid, "stat", 1024);
    const std::size_t close = stat.rfind(')');  // the command name may hold spaces
    if (close == std::string::npos || close + 2 > stat.size()) continue;
    std::istringstream fields(stat.substr(close + 2));
    std::string state;
    long ppid = 0;
    if (fields >> state >> ppid) children[ppid].push_back(pid);
  }
  double bytes = 0;
  std::vector<std::string> pending{std::to_string(root)};
  while (!pending.empty()) {
    const std::string pid = pending.back();
    pending.pop_back();
    const std::string rollup = proc_text(pid, "smaps_rollup", 4096);
    if (const std::size_t at = rollup.find("\nPss:"); at != std::string::npos) bytes += std::atof(rollup.c_str() + at + 5) * 1024;
    const auto found = children.find(std::atol(pid.c_str()));
    if (found != children.end()) pending.insert(pending.end(), found->second.begin(), found->second.end());
  }
  return bytes;
}

RunResult run_program(const std::string& program, const std::vector<std::string>& args, const std::vector<std::string>& env,
                      bool measure) {
  TempDir dir;
  const auto out_path = dir / "stdout", err_path = dir / "stderr";
  std::vector<std::string> argv_strings{program};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = merged_environment(env);
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  const pid_t pid = fork();
  if (pid == 0) {
    if (measure) setpgid(0, 0);
    const int in = open("/dev/null", O_RDONLY);
    const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    execve(program.c_str(), argv.data(), envp.data());
    _exit(127);
  }
  RunResult result;
  int status = 0;
  if (measure) {
    setpgid(pid, pid);  // as the child does: whichever runs first
    struct rusage usage {};
    while (wait4(pid, &status, WNOHANG, &usage) == 0) {
      result.peak_mb = std::max(result.peak_mb, tree_memory_bytes(pid) / (1024.0 * 1024.0));
      usleep(5000);  // reading smaps_rollup every millisecond slowed the measured tools by 10%
    }
    result.peak_mb = std::max(result.peak_mb, double(usage.ru_maxrss) / 1024.0);
  } else {
    waitpid(pid, &status, 0);
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = slurp(out_path);
  result.err = slurp(err_path);
  return result;
}

}  // namespace

RunResult run(const std::string& program, const std::vector<std::string>& args, const std::vector<std::string>& env) {
  return run_program(program, args, env, false);
}

std::string tool_path(const std::string& tool) {
  const RunResult r = run("/bin/sh", {"-c", "command -v " + tool});
  return r.exit_code == 0 ? r.out.substr(0, r.out.find('\n')) : std::string();
}

RunResult run_measured(const std::string& program, const std::vector<std::string>& args, const std::vector<std::string>& env) {
  return run_program(program, args, env, true);
}

std::string matbake_exe() {
  // MATBAKE_TEST_EXE: another build's matbake (an earlier commit's), to show a new test failing on it.
  const char* other = std::getenv("MATBAKE_TEST_EXE");
  return other && *other ? other : MATBAKE_EXE;
}

std::vector<std::string> matbake_environment(const std::vector<std::string>& env) {
  // The KTX2 encoder scripts/install-basisu.sh installs, unless the environment or `env` names one.
  std::vector<std::string> with_encoder = env;
  const std::filesystem::path installed = std::filesystem::path(MATBAKE_SOURCE_DIR) / "scripts" / "basisu" / "bin" / "basisu";
  if (!std::getenv("MATBAKE_BASISU") && ::access(installed.c_str(), X_OK) == 0) {
    with_encoder.insert(with_encoder.begin(), "MATBAKE_BASISU=" + installed.string());
  }
  return with_encoder;
}

RunResult matbake(const std::vector<std::string>& args, const std::vector<std::string>& env) {
  return run(matbake_exe(), args, matbake_environment(env));
}

}  // namespace matbake::test
