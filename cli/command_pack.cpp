#include <nlohmann/json.hpp>

#include <filesystem>

#include "commands.hpp"
#include "matbake/join.hpp"
#include "matbake/encoding_params.hpp"
#include "params_cli.hpp"
#include "matbake/material_params.hpp"
#include "silenced_stderr.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

std::string layout_help() {
  return "Layout: a preset (" + join(pack::builtin_layout_names(), ", ") + ") or a layout JSON file (docs/pack.md)";
}

}  // namespace

CLI::App* setup_pack(CLI::App& app, PackSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "pack",
      "Pack source maps into a layout's textures: Schüler's pair (A = Kd + mask, B = Ks + gloss), glTF\n"
      "metallicRoughness / ORM, Unreal ORM, Unity HDRP mask map, Unity URP. Constants are linear.\n"
      "Example: matbake pack --kd kd.png --mask 1 --ks 0.04 --gloss gloss.png -o out/brick_{texture}.png");
  cmd->add_option("--layout", s.layout, layout_help())->capture_default_str();
  add_source_options(*cmd, s.sources, {"transfer", "decode", "normal_y", "resize", "size", "bits"});
  add_output_options(*cmd, s.output, "textures");
  return cmd;
}

int run_pack(const PackSettings& s, const GlobalOptions& global) {
  auto layout = pack::find_layout(s.layout);
  if (!layout) return report_error(layout.error());
  auto sources = gather_sources(s.sources);
  if (!sources) return report_error(sources.error());
  auto written = write_textures(*layout, *sources, s.output, s.sources);
  if (!written) return report_error(written.error());
  if (global.json) {
    std::cout << nlohmann::json{{"command", "pack"}, {"layout", layout->name}, {"outputs", *written},
                                {"width", sources->width}, {"height", sources->height}}.dump(2)
              << "\n";
  } else if (!global.quiet) {
    for (const std::string& p : *written) std::cout << p << "\n";
  }
  return kOk;
}

CLI::App* setup_unpack(CLI::App& app, UnpackSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "unpack",
      "Split a layout's packed textures back into source maps: OUT_DIR/<source>.<format> (kd.png,\n"
      "mask.png, ...). The inverse of pack: unpack then pack gives the same 8-bit codes.");
  cmd->add_option("--layout", s.layout, layout_help())->capture_default_str();
  cmd->add_option("inputs", s.inputs, "The packed textures, in the layout's order")->required();
  cmd->add_option("-o,--out-dir", s.out_dir, "Folder for the source maps")->required();
  add_params(*cmd, pack::material_params(), s.options, "", "Options", nullptr, {"transfer", "decode", "normal_y", "bits", "format"});
  add_params(*cmd, image::encoding_params(), s.encoding, "", "Options");
  return cmd;
}

int run_unpack(const UnpackSettings& s, const GlobalOptions& global) {
  SourceSettings in;
  in.from = s.layout;
  in.inputs = s.inputs;
  in.options = s.options;
  if (auto problem = s.options.bits ? image::sample_type_problem("map." + s.options.format, *s.options.bits) : std::nullopt) {
    return report_error(Error{"--bits", *problem + " (--format " + s.options.format + ")", true});
  }
  auto sources = gather_sources(in);
  if (!sources) return report_error(sources.error());
  const pack::UnpackRequest request{s.out_dir,         s.options.format, s.options.bits, s.options.transfer,
                                    {s.inputs.begin(), s.inputs.end()}, s.encoding};
  Result<std::vector<fs::path>> paths = Error{"", ""};
  {
    SilencedStderr quiet;  // the image libraries' own messages: our error line says it
    paths = pack::write_maps(*sources, request);
  }
  if (!paths) return report_error(paths.error());
  const std::vector<std::string> written(paths->begin(), paths->end());
  if (global.json) {
    std::cout << nlohmann::json{{"command", "unpack"}, {"layout", s.layout}, {"outputs", written}}.dump(2) << "\n";
  } else if (!global.quiet) {
    for (const std::string& p : written) std::cout << p << "\n";
  }
  return kOk;
}

}  // namespace matbake::cli
