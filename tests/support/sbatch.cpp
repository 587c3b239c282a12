#include "support/sbatch.hpp"

#include <sstream>

#include "support/files.hpp"

namespace matbake::test {
namespace fs = std::filesystem;

fs::path stand_in_sbatch(const fs::path& dir) {
  const fs::path script = dir / "sbatch";
  write_bytes(script, "#!/usr/bin/env bash\n"
                      "log=" + (dir / "sbatch.log").string() + "\n"
                      "(IFS=$'\\t'; echo \"$*\") >>\"$log\"\n"
                      "id=$((100 + $(wc -l <\"$log\")))\n"
                      "array=\n"
                      "while [ $# -gt 0 ]; do\n"
                      "  case $1 in --array=*) array=${1#--array=}; array=${array%%\\%*} ;; --*) ;; *) break ;; esac\n"
                      "  shift\n"
                      "done\n"
                      "if [ -n \"$array\" ]; then\n"
                      "  for ((i = ${array%-*}; i <= ${array#*-}; i++)); do SLURM_ARRAY_TASK_ID=$i bash \"$@\" >/dev/null 2>&1; done\n"
                      "else\n"
                      "  bash \"$@\" >/dev/null 2>&1\n"
                      "fi\n"
                      "echo \"$id\"\n");
  fs::permissions(script, fs::perms::owner_exec, fs::perm_options::add);
  return script;
}

std::vector<std::vector<std::string>> sbatch_calls(const fs::path& dir) {
  std::vector<std::vector<std::string>> calls;
  if (!fs::exists(dir / "sbatch.log")) return calls;
  std::istringstream lines(read_bytes(dir / "sbatch.log"));
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> args;
    std::istringstream fields(line);
    for (std::string a; std::getline(fields, a, '\t');) args.push_back(a);
    calls.push_back(args);
  }
  return calls;
}

}  // namespace matbake::test
