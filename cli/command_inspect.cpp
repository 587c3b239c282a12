#include <iostream>

#include "commands.hpp"
#include "matbake/inspect.hpp"
#include "silenced_stderr.hpp"

namespace matbake::cli {

CLI::App* setup_inspect(CLI::App& app, InspectSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "inspect",
      "What a file holds, without building (docs/inspect.md): a .gltf/.glb's scenes, meshes, materials, textures\n"
      "(size, codec, levels, bytes, GPU memory) and images; a .ktx2's header, DFD and levels; a manifest's jobs\n"
      "with their state, and for each scene the texture sizes, codecs and estimated bytes it would deliver.\n"
      "--json for the schema in docs/inspect.schema.json");
  cmd->add_option("path", s.path, "A .gltf, .glb, .ktx2 or manifest (.toml)")->required();
  return cmd;
}

int run_inspect(const InspectSettings& s, const GlobalOptions& global) {
  SilencedStderr quiet;  // the image libraries' own messages: the error line says it
  auto inspected = inspect::inspect(s.path);
  quiet.restore();
  if (!inspected) return report_error(inspected.error(), key_mention);
  if (global.json) {
    std::cout << nlohmann::json{{"command", "inspect"}, {"inspected", *inspected}}.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  } else if (!global.quiet) {
    std::cout << inspect::text(*inspected);
  }
  return kOk;
}

}  // namespace matbake::cli
