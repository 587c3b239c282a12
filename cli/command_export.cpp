#include <nlohmann/json.hpp>

#include <cstdio>

#include "commands.hpp"
#include "ao_options.hpp"
#include "matbake/export_params.hpp"
#include "params_cli.hpp"
#include "matbake/material_params.hpp"
#include "material_sources.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/export.hpp"
#include "matbake/output_check.hpp"
#include "matbake/report_json.hpp"
#include "silenced_stderr.hpp"

namespace matbake::cli {
namespace {

// "NAME=[LAYOUT:]FILE,FILE..." → the material's name and its maps (layout schuler by default).
Result<exporter::MaterialMaps> parse_material(const std::string& text, const pack::MaterialOptions& options) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == text.size()) {
    return Error{"", "--material '" + text + "': use NAME=A.png,B.png (a Schüler pair) or NAME=LAYOUT:FILE,...", true};
  }
  exporter::MaterialMaps m;
  m.material = text.substr(0, equals);
  std::string rest = text.substr(equals + 1), layout = "schuler";
  // A layout name has no dot or slash; a file path usually has both.
  if (const std::size_t colon = rest.find(':');
      colon != std::string::npos && rest.substr(0, colon).find_first_of("./") == std::string::npos) {
    layout = rest.substr(0, colon);
    rest = rest.substr(colon + 1);
  }
  std::vector<std::string> files;
  for (std::size_t start = 0; start <= rest.size();) {
    const std::size_t comma = std::min(rest.find(',', start), rest.size());
    files.push_back(rest.substr(start, comma - start));
    start = comma + 1;
  }
  auto found = pack::find_layout(layout);
  if (!found) return found.error();
  SilencedStderr quiet;
  auto maps = pack::read_packed(*found, {files.begin(), files.end()}, options);
  if (!maps) return maps.error();
  m.maps = std::move(*maps);
  return m;
}

}  // namespace

CLI::App* setup_export(CLI::App& app, ExportSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a glTF scene again as glTF 2.0 metal-rough: materials given as Schüler pairs (--material) or in\n"
      "KHR_materials_pbrSpecularGlossiness converted (error reported; KHR_materials_specular where a dielectric's\n"
      "F0 is not 0.04), occlusion packed into ORM, AO baked in (per vertex with --ao-samples, or into each\n"
      "material's ORM red channel with --ao-texture SIZE; any --ao-* option turns AO on), and only what the\n"
      "default scene reaches written.\n"
      "Example: matbake export scene.gltf -o out/scene.glb --material Brick=brick_a.png,brick_b.png --ao-samples 64");
  cmd->add_option("scene", s.scene, "Input .gltf or .glb")->required();
  cmd->add_option("-o,--output", s.output, "Output .gltf (+ .bin and PNGs beside it) or .glb")->required();
  cmd->add_option("--material", s.materials,
                  "NAME=A.png,B.png: material NAME (or its index) from a Schüler pair; NAME=LAYOUT:FILE,... from\n"
                  "any pack layout's textures (e.g. gltf-metal-rough:base.png,mr.png). Repeatable");
  add_params(*cmd, pack::material_params(), s.material_options, "", "Options", nullptr, {"transfer", "decode", "normal_y"});
  // AO is baked when any --ao-* is given, as a manifest's ao = { ... }.
  add_tree(*cmd, exporter::request_tree(), s.options, s.given,
           {"Options", "Options", "Texture delivery (docs/delivery.md)", "Ambient occlusion"});
  add_dump_texture(*cmd, s.dump_texture, "ao-", "Ambient occlusion");
  cmd->add_option("--report", s.report, "Also write the report as JSON to this file");
  return cmd;
}

int run_export(const ExportSettings& s, const GlobalOptions& global) {
  exporter::Options options = s.options;
  if (Status st = finish_tree(exporter::request_tree(), options, s.given); !st) return report_error(st.error());
  if (!s.dump_texture.empty()) {
    if (!options.ao) return report_error(Error{"--ao-dump-texture", "applies only with --ao-texture as well", true});
    if (Status st = set_dump_texture(*options.ao, s.dump_texture, "ao-"); !st) return report_error(st.error());
  }
  for (const std::string& text : s.materials) {
    auto m = parse_material(text, s.material_options);
    if (!m) return report_error(m.error());
    options.materials.push_back(std::move(*m));
  }
  if (!s.report.empty()) {
    auto inputs = exporter::scene_files(s.scene);
    if (!inputs) return report_error(inputs.error());
    const NamedOutput outputs[] = {{s.output, "glTF output"}, {s.report, "report"}};
    if (Status st = check_outputs(outputs, *inputs); !st) return report_error(st.error());
  }
  Result<exporter::Report> report = Error{"", ""};
  {
    SilencedStderr quiet;  // the image libraries' own messages on a bad texture: our error line says it
    report = exporter::export_scene(s.scene, s.output, options);
  }
  if (!report) return report_error(report.error());
  nlohmann::json doc = {{"command", "export"}};
  doc.update(to_json(*report));
  if (!s.report.empty()) {
    if (Status st = write_file_atomically(s.report, doc.dump(2) + "\n"); !st) return report_error(st.error());
  }
  if (global.json) {
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet) {
    for (const std::string& p : report->written) std::cout << p << "\n";
    for (const exporter::MaterialReport& m : report->materials) {
      std::printf("material %d '%s': %s, %s", m.index, m.name.c_str(), m.action.c_str(), m.alpha_mode.c_str());
      if (m.conversion) {
        std::printf("; diffuse ΔE*ab mean %.3g, |ΔF0| mean %.3g, lobe error mean %.3g%%", m.conversion->errors.diffuse_delta_e.mean,
                    m.conversion->errors.specular.mean, 100 * m.conversion->errors.lobe.mean);
      }
      if (m.specular_color_factor) std::printf("; KHR_materials_specular %.4g", *m.specular_color_factor);
      if (m.ior) std::printf("; KHR_materials_ior %.4g", *m.ior);
      std::printf("\n");
    }
    for (const std::string& skipped : report->skipped) std::cout << "left out: " << escape_control(skipped) << "\n";
    for (const std::string& note : report->geometry) std::cout << "geometry: " << escape_control(note) << "\n";
    for (const std::string& note : report->ao_notes) std::cout << "note: " << escape_control(note) << "\n";
    print_texture_reports(report->ao_textures);
  }
  return kOk;
}

}  // namespace matbake::cli
