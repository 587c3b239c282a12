#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "matbake/validate_params.hpp"
#include "params_cli.hpp"
#include "matbake/material_table.hpp"
#include "matbake/output_check.hpp"
#include "matbake/report_json.hpp"
#include "matbake/validate.hpp"
#include "silenced_stderr.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

nlohmann::json rgb(const glm::dvec3& v) { return {v.r, v.g, v.b}; }

std::vector<int> codes(const glm::dvec3& f0, color::Transfer transfer) {
  std::vector<int> c;
  for (int i = 0; i < 3; ++i) c.push_back(color::quantize(transfer, 8, float(f0[i])));
  if (c[0] == c[1] && c[1] == c[2]) c.resize(1);
  return c;
}

std::string join(const std::vector<int>& v) {
  std::string s;
  for (int x : v) s += (s.empty() ? "" : ";") + std::to_string(x);
  return s;
}

}  // namespace

CLI::App* setup_materials(CLI::App& app, MaterialsSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "materials",
      "List the material table (presets/materials.toml): F0 linear, as 8-bit codes via gamma 2.2 and via sRGB,\n"
      "IOR, source.");
  cmd->add_option("--table", s.table, "Another table file in the same TOML format");
  return cmd;
}

int run_materials(const MaterialsSettings& s, const GlobalOptions& global) {
  auto table = material_table::table_or_builtin(s.table);
  if (!table) return report_error(table.error());
  nlohmann::json list = nlohmann::json::array();
  for (const material_table::Material& m : *table) {
    nlohmann::json j = {{"name", m.name},
                        {"class", material_table::class_name(m.material_class)},
                        {"f0_linear", rgb(m.f0)},
                        {"code_gamma22", codes(m.f0, color::Transfer::gamma22)},
                        {"code_srgb", codes(m.f0, color::Transfer::srgb)},
                        {"source", m.source}};
    if (m.f0_range) j["f0_range"] = *m.f0_range;
    if (!m.table_code.empty()) j["table_code"] = m.table_code;
    if (m.ior) j["ior"] = *m.ior;
    if (m.ior_n) j["ior_n"] = rgb(*m.ior_n), j["ior_k"] = rgb(*m.ior_k);
    list.push_back(std::move(j));
  }
  if (global.json) {
    std::cout << nlohmann::json{{"command", "materials"}, {"materials", list}}.dump(2) << "\n";
    return kOk;
  }
  std::printf("%-16s %-13s %-22s %-12s %-12s %s\n", "name", "class", "F0 (linear)", "8-bit g2.2", "8-bit sRGB", "IOR");
  for (const material_table::Material& m : *table) {
    char f0[64];
    if (m.f0.r == m.f0.g && m.f0.g == m.f0.b) {
      std::snprintf(f0, sizeof f0, "%.4f", m.f0.r);
    } else {
      std::snprintf(f0, sizeof f0, "%.3f %.3f %.3f", m.f0.r, m.f0.g, m.f0.b);
    }
    char ior[64] = "";
    if (m.ior) std::snprintf(ior, sizeof ior, "%.4f", *m.ior);
    if (m.ior_n) std::snprintf(ior, sizeof ior, "n %.2f %.2f %.2f, k %.2f %.2f %.2f", m.ior_n->r, m.ior_n->g, m.ior_n->b,
                               m.ior_k->r, m.ior_k->g, m.ior_k->b);
    std::printf("%-16s %-13s %-22s %-12s %-12s %s\n", m.name.c_str(), std::string(material_table::class_name(m.material_class)).c_str(),
                f0, join(codes(m.f0, color::Transfer::gamma22)).c_str(), join(codes(m.f0, color::Transfer::srgb)).c_str(),
                ior);
  }
  return kOk;
}

CLI::App* setup_validate(CLI::App& app, ValidateSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "validate",
      "Check every texel's F0 (and diffuse colour) against physics: below any real material (< 0.02),\n"
      "dielectric, gem, semiconductor gap (0.2-0.45, flagged), metal (>= 0.45, flagged with a diffuse colour);\n"
      "coloured dielectric specular, implausible albedo. Inputs: a Schüler pair (--from schuler A.png B.png),\n"
      "pair B alone (--ks B.png), or metal-rough maps (--from gltf-metal-rough base.png mr.png, or --base-color\n"
      "and --metallic). Exit 0 clean, 3 when the flagged share exceeds --max-violations, 1 bad input.");
  add_source_options(*cmd, s.sources, {"transfer", "decode", "resize", "size"});
  cmd->add_option("--material", s.material, "Also compare with a table entry (see `matbake materials`)");
  cmd->add_option("--materials-table", s.table, "Another table file in the TOML format of presets/materials.toml");
  add_params(*cmd, validate::options_params(), s.options, "", "Options");
  cmd->add_option("--heatmap", s.heatmap, "Write a false-colour class map (.png; legend in the README)");
  cmd->add_option("--report", s.report, "Also write the report as JSON to this file (as `matbake build` writes it)");
  return cmd;
}

int run_validate(const ValidateSettings& s, const GlobalOptions& global) {
  auto table = material_table::table_or_builtin(s.table);
  if (!table) return report_error(table.error());
  validate::Options options = s.options;
  options.class_map = !s.heatmap.empty();
  if (!s.material.empty()) {
    auto material = material_table::lookup(*table, s.material);
    if (!material) return report_error(material.error());
    options.material = *material;
  }
  const NamedOutput outputs[] = {{s.heatmap, "heatmap"}, {s.report, "report"}};
  if (Status st = check_outputs(outputs, input_files(s.sources)); !st) return report_error(st.error());
  auto sources = gather_sources(s.sources);
  if (!sources) return report_error(sources.error());
  auto report = validate::validate_maps(*sources, options);
  if (!report) return report_error(report.error());
  if (!s.heatmap.empty()) {
    Status written = success();
    {
      SilencedStderr quiet;  // the image libraries' own messages: our error line says it
      written = validate::write_heatmap(*report, s.heatmap);
    }
    if (!written) return report_error(written.error());
  }
  if (!s.report.empty()) {
    if (Status st = write_validation_report(*report, options, s.report); !st) return report_error(st.error());
  }
  const bool failed = !validate::passed(*report, options);
  const int exit_code = failed && options.gate ? kViolations : kOk;

  nlohmann::json doc = {{"command", "validate"}};
  doc.update(to_json(*report, options));
  doc["max_violations"] = options.max_violations;
  doc["passed"] = !failed;
  doc["gate"] = options.gate;
  if (!s.heatmap.empty()) doc["heatmap"] = s.heatmap;
  if (global.json) {
    std::cout << doc.dump(2) << "\n";
  } else if (!global.quiet) {
    std::printf("%d x %d: %zu texels checked, %zu masked\n", report->width, report->height, report->checked,
                report->masked);
    std::printf("  classes: below %zu · dielectric %zu · gem %zu · semiconductor gap %zu · metal %zu\n",
                report->class_counts[0], report->class_counts[1], report->class_counts[2], report->class_counts[3],
                report->class_counts[4]);
    if (options.material) {
      std::printf("  %s within %.0f%%: %zu texels (%.2f%%)\n", options.material->name.c_str(), 100 * options.tolerance,
                  report->material_within,
                  report->checked ? 100.0 * double(report->material_within) / double(report->checked) : 0.0);
    }
    std::printf("  flagged: %zu texels (%.4f%%, allowed %.4f%%)%s\n", report->violations,
                100 * report->violation_fraction(), 100 * options.max_violations,
                failed ? (options.gate ? ": FAILED" : ": over the limit (advisory: gate off)") : "");
    for (int b = 0; b < validate::kFlagCount; ++b) {
      if (report->flag_counts[std::size_t(b)]) {
        std::printf("    %-22s %zu: %s\n", std::string(validate::flag_name(b)).c_str(), report->flag_counts[std::size_t(b)],
                    std::string(validate::flag_meaning(b, report->vocabulary)).c_str());
      }
    }
    for (const validate::Texel& t : report->worst) {
      std::printf("    at (%d, %d): %s, F0 %.4f %.4f %.4f: %s\n", t.x, t.y,
                  std::string(material_table::f0_class_name(t.f0_class)).c_str(), t.f0.r, t.f0.g, t.f0.b,
                  validate::flag_names(t.flags).c_str());
    }
  }
  return exit_code;
}

}  // namespace matbake::cli
