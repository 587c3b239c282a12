#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "commands.hpp"
#include "matbake/report_json.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/workflow_maps.hpp"

namespace matbake::cli {
namespace {

using workflow::ErrorStats;

std::string line(const char* label, const ErrorStats& s, double scale, const char* unit) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "  %-22s mean %.4g%s  max %.4g%s at (%d, %d)\n", label, s.mean * scale, unit,
                s.max * scale, unit, s.max_x, s.max_y);
  return buffer;
}

std::string describe(const workflow::ConversionErrors& e) {
  return line("diffuse ΔE*ab", e.diffuse_delta_e, 1, "") + line("specular |ΔF0|", e.specular, 1, "") +
         line("lobe error (rel. RMS)", e.lobe, 100, "%");
}

Status write_report(const std::string& path, const nlohmann::json& doc) {
  auto file = AtomicFile::create(path);
  if (!file) return file.error();
  {
    std::ofstream out(file->temp_path());
    out << doc.dump(2) << "\n";
    if (!out) return Error{path, "cannot write"};
  }
  return file->commit();
}

}  // namespace

CLI::App* setup_workflow(CLI::App& app, WorkflowSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "workflow",
      "Convert between Schüler's specular workflow (Kd, Ks, gloss) and the metalness workflow (base colour,\n"
      "metallic, roughness), write the target layout's textures and report the error of the conversion\n"
      "(and, to metal-rough, of the Khronos spec-gloss converter on the same texels).\n"
      "Example: matbake workflow --from schuler A.png B.png --layout gltf-orm -o out/brick_{texture}.png");
  cmd->add_option("--layout,--to", s.to, "Target layout: a preset or a layout JSON file (--to: its older name)")->required();
  cmd->add_option("--report", s.report, "Also write the error report as JSON to this file");
  add_source_options(*cmd, s.sources, {"transfer", "decode", "normal_y", "resize", "size", "bits", "mapping"});
  add_output_options(*cmd, s.output, "textures");
  return cmd;
}

int run_workflow(const WorkflowSettings& s, const GlobalOptions& global) {
  auto layout = pack::find_layout(s.to);
  if (!layout) return report_error(layout.error());
  auto sources = gather_sources(s.sources);
  if (!sources) return report_error(sources.error());

  auto converted = workflow::in_layout_workflow(std::move(*sources), *layout, s.sources.options.mapping);
  if (!converted) return report_error(converted.error());
  if (!converted->direction) {
    return report_error(Error{"", "nothing to convert: give Schüler sources (--kd, --ks, --gloss) for a metal-rough "
                                  "layout or metal-rough ones (--base-color, --metallic, --roughness) for schuler; "
                                  "`matbake pack` packs without converting",
                              true});
  }
  auto written = write_textures(*layout, converted->maps, s.output, s.sources, {{s.report, "report"}});
  if (!written) return report_error(written.error());

  const workflow::ConversionReport& report = converted->report;
  const std::string direction(workflow::direction_name(*converted->direction));
  const std::string mapping(workflow::roughness_mapping_name(s.sources.options.mapping));
  nlohmann::json doc = {{"command", "workflow"}, {"layout", layout->name}, {"outputs", *written}};
  doc.update(to_json(*converted, s.sources.options.mapping));
  const bool spec_gloss_source = *converted->direction == workflow::Direction::metal_rough_from_spec_gloss;
  if (!s.report.empty()) {
    if (Status st = write_report(s.report, doc); !st) return report_error(st.error());
  }
  if (global.json) {
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet) {
    for (const std::string& p : *written) std::cout << p << "\n";
    std::cout << direction << ", " << converted->maps.width << "x" << converted->maps.height << ", roughness mapping "
              << mapping << "; errors of what the result renders against the source:\n"
              << describe(report.errors);
    if (spec_gloss_source) {
      std::cout << "Khronos spec-gloss converter (roughness = 1 - gloss) on the same texels:\n"
                << describe(report.khronos_errors);
      const auto& d = report.dielectric;
      if (d.texels > 0) {
        char buffer[300];
        std::snprintf(buffer, sizeof buffer,
                      "%zu dielectric texels have F0 != 0.04 (mean %.4f): KHR_materials_ior %.4f or "
                      "KHR_materials_specular specularColorFactor %.4f; |ΔF0| mean %.4f without them, %.4f with\n",
                      d.texels, d.mean_f0, d.ior, d.specular_color_factor, d.error_without_extensions.mean,
                      d.error_with_extensions.mean);
        std::cout << buffer;
      }
    }
  }
  return kOk;
}

}  // namespace matbake::cli
