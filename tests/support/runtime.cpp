#include "support/runtime.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "matbake/image.hpp"
#include "matbake/subprocess.hpp"

namespace matbake::test {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

const fs::path kHarness = fs::path(MATBAKE_SOURCE_DIR) / "tests" / "runtime";
constexpr int kSkipExit = 77;  // render.mjs: Chromium cannot be started here

RuntimeTexture texture_from(const json& t) {
  RuntimeTexture out;
  out.material = t.at("material");
  out.slot = t.at("slot");
  out.texture = t.at("texture");
  out.color_space = t.at("colorSpace");
  out.compressed = t.at("compressed");
  out.width = t.at("width");
  out.height = t.at("height");
  out.levels = t.at("levels");
  out.generate_mipmaps = t.at("generateMipmaps");
  out.min_filter = t.at("minFilter");
  return out;
}

}  // namespace

// The harness's npm packages, or why they are missing.
bool harness_installed(std::string& why_not) {
  for (const char* package : {"three", "puppeteer-core"}) {
    if (!fs::exists(kHarness / "node_modules" / package / "package.json")) {
      why_not = std::string("the runtime harness is not installed (no ") + package + "; bash scripts/install-runtime.sh)";
      return false;
    }
  }
  return true;
}

// Runs `node SCRIPT ARGS...` of the harness within `limit`: true when it ran; false with `why_not`
// when the harness or Chromium is missing here; a failure throws.
bool run_harness(const std::string& script, std::vector<std::string> args, std::chrono::seconds limit, std::string& why_not) {
  if (!harness_installed(why_not)) return false;
  SubprocessRequest request;
  request.program = "/usr/bin/env";
  request.args = {"node", (kHarness / script).string()};
  request.args.insert(request.args.end(), args.begin(), args.end());
  request.time_limit = limit;
  const SubprocessResult result = run_supervised(request);
  if (result.status == kSkipExit) {
    why_not = "no runtime here: " + result.error_line();
    return false;
  }
  if (result.status != 0) throw std::runtime_error(script + " failed: " + result.output_tail);
  return true;
}

std::optional<nlohmann::json> check_page_in_chromium(const fs::path& page, const fs::path& screenshot, std::string& why_not) {
  const fs::path result_file = page.parent_path() / (page.stem().string() + ".chromium.json");
  std::vector<std::string> args{page.string(), "--out", result_file.string(), "--timeout", "60"};
  if (!screenshot.empty()) args.insert(args.end(), {"--screenshot", screenshot.string()});
  if (!run_harness("check_page.mjs", args, std::chrono::seconds(90), why_not)) return std::nullopt;
  std::ifstream in(result_file);
  return json::parse(in);
}

std::optional<std::vector<float>> mikktspace_in_three(const fs::path& folder, const std::vector<float>& positions,
                                                      const std::vector<float>& normals, const std::vector<float>& texcoords,
                                                      std::string& why_not) {
  const auto write = [&](const char* name, const std::vector<float>& values) {
    std::ofstream(folder / name, std::ios::binary).write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(float)));
    return (folder / name).string();
  };
  const std::vector<std::string> args{write("positions.f32", positions), write("normals.f32", normals),
                                      write("texcoords.f32", texcoords), (folder / "tangents.f32").string()};
  if (!run_harness("mikktspace.mjs", args, std::chrono::seconds(60), why_not)) return std::nullopt;
  std::ifstream in(folder / "tangents.f32", std::ios::binary);
  std::vector<float> tangents(positions.size() / 3 * 4);
  in.read(reinterpret_cast<char*>(tangents.data()), std::streamsize(tangents.size() * sizeof(float)));
  if (in.gcount() != std::streamsize(tangents.size() * sizeof(float))) throw std::runtime_error("mikktspace.mjs wrote a short file");
  return tangents;
}

std::optional<std::map<std::string, RuntimeModel>> render_in_three(
    const fs::path& folder, const std::vector<std::pair<std::string, fs::path>>& models, std::string& why_not) {
  std::vector<std::string> args{"--out", folder.string(), "--timeout", "150"};
  for (const auto& [name, file] : models) args.push_back(name + "=" + file.string());
  if (!run_harness("render.mjs", args, std::chrono::seconds(180), why_not)) return std::nullopt;

  std::ifstream in(folder / "report.json");
  const json report = json::parse(in);
  std::map<std::string, RuntimeModel> out;
  for (const auto& [name, model] : report.at("models").items()) {
    RuntimeModel& m = out[name];
    for (const json& t : model.at("textures")) m.textures.push_back(texture_from(t));
    for (const json& line : model.at("console")) m.console.push_back(line);
    for (const std::string& view : kRuntimeViews) m.renders[view] = folder / (name + "-" + view + ".png");
  }
  return out;
}

std::string color_space_of_slot(const std::string& slot) {
  return slot == "baseColorTexture" || slot == "emissiveTexture" ? "srgb" : "";
}

}  // namespace matbake::test
