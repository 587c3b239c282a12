#include "support/gltf_validator.hpp"

#include <nlohmann/json.hpp>

#include "support/run.hpp"

namespace matbake::test {
namespace fs = std::filesystem;

std::optional<ValidatorReport> validate_gltf(const fs::path& file, std::string& why_not) {
  const fs::path folder = fs::path(MATBAKE_SOURCE_DIR) / "scripts" / "gltf-validator";
  if (!fs::exists(folder / "node_modules" / "gltf-validator" / "package.json")) {
    why_not = "the glTF-Validator is not installed (bash scripts/install-gltf-validator.sh)";
    return std::nullopt;
  }
  const RunResult r = run("/usr/bin/env", {"node", (folder / "validate.js").string(), file.string(), "--json"});
  if (r.exit_code != 0 && r.exit_code != 1) {
    why_not = "the glTF-Validator could not run: " + r.err;
    return std::nullopt;
  }
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const nlohmann::json& issues = report["issues"];
  ValidatorReport out;
  out.errors = issues["numErrors"];
  out.warnings = issues["numWarnings"];
  out.infos = issues["numInfos"];
  out.summary = file.string() + ":";
  for (const auto& m : issues["messages"]) {
    const int severity = m["severity"];
    const std::string line = m["code"].get<std::string>() + " " + m.value("pointer", "");
    if (severity <= 1) out.error_and_warning_codes.push_back(line);
    if (severity <= 2) out.summary += "\n  " + line + ": " + m.value("message", "");
  }
  return out;
}

}  // namespace matbake::test
