#include <nlohmann/json.hpp>

#include <filesystem>

#include "commands.hpp"
#include "silenced_stderr.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

std::string layout_help() {
  std::string names;
  for (const std::string& n : pack::builtin_layout_names()) names += (names.empty() ? "" : ", ") + n;
  return "Layout: a preset (" + names + ") or a layout JSON file (docs/pack.md)";
}

}  // namespace

CLI::App* setup_pack(CLI::App& app, PackSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "pack",
      "Pack source maps into a layout's textures: Schüler's pair (A = Kd + mask, B = Ks + gloss), glTF\n"
      "metallicRoughness / ORM, Unreal ORM, Unity HDRP mask map, Unity URP. Constants are linear.\n"
      "Example: matbake pack --kd kd.png --mask 1 --ks 0.04 --gloss gloss.png -o out/brick_{texture}.png");
  cmd->add_option("--layout", s.layout, layout_help())->capture_default_str();
  add_source_options(*cmd, s.sources);
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
  cmd->add_option("--format", s.format, "Extension of the source maps")->capture_default_str();
  cmd->add_option("--bits", s.bits, "8, 16, half or float (default: 8; half for exr)");
  cmd->add_option("--transfer", s.transfer, "Curve of 8-bit colour channels, read and written: srgb or gamma2.2")
      ->capture_default_str();
  return cmd;
}

int run_unpack(const UnpackSettings& s, const GlobalOptions& global) {
  SourceSettings in;
  in.from = s.layout;
  in.inputs = s.inputs;
  in.transfer = s.transfer;
  auto sources = gather_sources(in);
  if (!sources) return report_error(sources.error());
  auto transfer = parse_transfer(s.transfer, "--transfer");
  if (!transfer) return report_error(transfer.error());
  auto type = s.bits.empty() ? (s.format == "exr" ? image::SampleType::half : image::SampleType::u8)
                             : image::sample_type_from_name(s.bits).value_or(image::SampleType::u8);
  if (!s.bits.empty() && !image::sample_type_from_name(s.bits)) {
    return report_error(Error{"", "--bits '" + s.bits + "': use 8, 16, half or float", true});
  }
  std::error_code ec;
  fs::create_directories(s.out_dir, ec);
  std::vector<std::string> written;
  for (const auto& [name, map] : sources->maps) {
    const fs::path path = fs::path(s.out_dir) / (name + "." + s.format);
    for (const std::string& input : s.inputs) {
      if (fs::equivalent(path, input, ec)) {
        return report_error(Error{path.string(), "is an input; matbake never overwrites its inputs", true});
      }
    }
    const bool colour = material::find_source(name)->kind == material::SourceKind::color;
    SilencedStderr quiet;
    if (Status st = image::write_image(map, path, pack::write_options(colour, {type, *transfer})); !st) {
      return report_error(st.error());
    }
    written.push_back(path.string());
  }
  if (global.json) {
    std::cout << nlohmann::json{{"command", "unpack"}, {"layout", s.layout}, {"outputs", written}}.dump(2) << "\n";
  } else if (!global.quiet) {
    for (const std::string& p : written) std::cout << p << "\n";
  }
  return kOk;
}

}  // namespace matbake::cli
