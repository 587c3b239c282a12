#include "support/basisu.hpp"

#include <cstdlib>
#include <filesystem>

#include "support/run.hpp"

namespace matbake::test {

std::string basisu_for_tests(std::string& why_not) {
  const char* named = std::getenv("MATBAKE_BASISU");
  const std::string path = named && *named ? std::string(named)
                                           : (std::filesystem::path(MATBAKE_SOURCE_DIR) / "scripts" / "basisu" / "bin" / "basisu").string();
  const RunResult r = run(path, {"-version"});
  if (r.exit_code != 0 || r.out.find("Basis Universal") == std::string::npos) {
    why_not = "basisu is not installed at " + path + " (bash scripts/install-basisu.sh, or set MATBAKE_BASISU)";
    return "";
  }
  return path;
}

}  // namespace matbake::test
