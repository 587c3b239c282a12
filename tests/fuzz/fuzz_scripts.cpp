// The plan writers with hostile words: the input split at 0x01 bytes into the manifest's folder, a
// material's name and the output folder, written into a Ninja file and the Slurm scripts. Either
// the writer refuses (an error), or every line it writes is one it means to write (no word starts a
// line of its own) and each word reads back unchanged through the quoting its language applies.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "matbake/cluster.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/script_text.hpp"

namespace fs = std::filesystem;
using namespace matbake;

namespace {

void check(bool holds) {
  if (!holds) std::abort();
}

// A POSIX shell word read back: single-quoted runs and plain characters.
std::string shell_read(const std::string& word) {
  std::string out;
  bool quoted = false;
  for (std::size_t i = 0; i < word.size(); ++i) {
    if (word[i] == '\'') {
      quoted = !quoted;
    } else if (!quoted && word[i] == '\\' && i + 1 < word.size()) {
      out += word[++i];
    } else {
      check(quoted || std::string_view("_./:=%@+,-").find(word[i]) != std::string_view::npos || std::isalnum(static_cast<unsigned char>(word[i])));
      out += word[i];
    }
  }
  check(!quoted);
  return out;
}

// A Ninja path read back: "$x" is x; an unescaped ' ', ':', '|' or line break would end the path.
std::string ninja_read(const std::string& path) {
  std::string out;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '$') {
      check(i + 1 < path.size());
      out += path[++i];
    } else {
      check(std::string_view(" :|\n\r").find(path[i]) == std::string_view::npos);
      out += path[i];
    }
  }
  return out;
}

void check_lines(const std::string& text, const std::vector<std::string_view>& starts) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    bool known = line.empty();
    for (std::string_view s : starts) known = known || line.rfind(s, 0) == 0;
    check(known);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> parts(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 1 && parts.size() < 3) parts.emplace_back();
    else parts.back() += char(data[i]);
  }
  parts.resize(3);
  for (const std::string& p : parts) {
    check(shell_read(shell_word(p)) == p || p.empty());
    if (auto n = ninja_path(p)) check(ninja_read(*n) == p);
  }
  pipeline::Manifest m;
  m.folder = "/" + parts[0];
  m.file = m.folder / "m.toml";
  m.output = "/" + parts[2];
  pipeline::Plan plan;
  plan.state_folder = m.output / ".matbake";
  pipeline::Job job;
  job.name = "material:" + parts[1];
  job.inputs = {m.folder / (parts[1] + ".png")};
  job.outputs.textures = {m.output / "materials" / (parts[1] + "_orm.png")};
  plan.jobs = {job};
  if (auto ninja = pipeline::ninja_text(m, plan, "/usr/bin/matbake", m.output / "build.ninja")) {
    check_lines(*ninja, {"# ", "ninja_required_version = ", "matbake = ", "manifest = ", "output = ", "plan_file = ", "rule matbake",
                         "  command = ", "  description = ", "  depfile = ", "  deps = ", "  restat = ", "  generator = ",
                         "build ", "  job = ", "  depfile_path = ", "  depfile_word = "});
  }
  pipeline::SlurmSubmission submission;
  submission.array = {{&plan.jobs[0], 64, {}}};
  if (auto scripts = pipeline::slurm_scripts(m, submission, {}, {m.output / "slurm", "/usr/bin/matbake"})) {
    const std::vector<std::string_view> starts = {"#", "set -euo pipefail", "materials=(", "job=${1:-", "exec ", "sbatch=", "mkdir -p ",
                                                  "array=", "echo "};
    check_lines(scripts->job, starts);
    check_lines(scripts->submit, starts);
  }
  return 0;
}
