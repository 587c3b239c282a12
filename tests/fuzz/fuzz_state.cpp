// matbake's state files as anyone who can write into OUT/.matbake leaves them: the input's bytes as
// made.json and as a job's stamp, read as a build reads them, every entry of the log offered to the
// output gate (dry run: nothing is removed). Nothing may throw or crash, no state file may cost more
// than its size limit, and the gate may accept only a plain path below the output folder.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "lib/src/pipeline/made_log.hpp"
#include "lib/src/pipeline/state.hpp"
#include "matbake/output_gate.hpp"

namespace fs = std::filesystem;
using namespace matbake;

namespace {

const pipeline::StampRoots& roots() {
  static const pipeline::StampRoots r = [] {
    const fs::path base = fs::temp_directory_path() / ("matbake-fuzz-state-" + std::to_string(getpid()));
    fs::create_directories(base / "out/.matbake");
    return pipeline::StampRoots{base / "out/.matbake", base, base / "out"};
  }();
  return r;
}

void write(const fs::path& file, const std::uint8_t* data, std::size_t size) {
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const pipeline::StampRoots& r = roots();
  write(r.state_folder / "made.json", data, size);
  write(r.state_folder / "material-m.json", data, size);
  std::string problem;
  const pipeline::MadeLog log = pipeline::read_made_log(r, problem);
  pipeline::Job job;
  job.name = "material:m";
  job.options = "{}";
  std::map<fs::path, std::string> recorded;
  (void)pipeline::out_of_date_reason(job, r, false, &recorded);
  static const OutputGate gate(r.outputs, {});
  const auto offer = [&](const std::string& path, const std::string& hash) {
    const RemoveResult result = gate.remove_made(path, hash, true);
    if (result.outcome == RemoveOutcome::removed && !recorded_path_problem(path).empty()) std::abort();
  };
  for (const auto& [job_name, files] : log.jobs) {
    for (const auto& [path, hash] : files) offer(path, hash);
  }
  for (const auto& [path, hash] : log.stale) offer(path, hash);
  return 0;
}
