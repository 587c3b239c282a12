#pragma once
// What a long call is doing now, for a progress display (a build's running jobs, docs/build.md
// "Progress"). Reported from the thread doing the work or from worker threads; a display must
// take it from any thread. Nothing depends on it being set.
#include <functional>
#include <string_view>

namespace matbake {

// The parts of a job whose work is estimated apart (pipeline::JobWork), in the order they run.
enum class Phase { read, ao, textures, write };

// `what`: the stage in words ("encoding textures 3 of 12"); `fraction`: of the phase done, 0 to 1.
using StageReport = std::function<void(Phase phase, std::string_view what, double fraction)>;

inline void report_stage(const StageReport& report, Phase phase, std::string_view what, double fraction = 0) {
  if (report) report(phase, what, fraction);
}

}  // namespace matbake
