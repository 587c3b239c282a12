#include <nlohmann/json.hpp>

#include <cstdio>

#include "commands.hpp"
#include "ao_options.hpp"
#include "matbake/bake_ao_params.hpp"
#include "params_cli.hpp"
#include "matbake/export.hpp"
#include "matbake/report_json.hpp"

namespace matbake::cli {

CLI::App* setup_bake_ao(CLI::App& app, BakeAoSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "bake-ao",
      "Bake ambient obscurance (ch. 12, eq. 12.72) of a glTF scene's triangles with Embree: cosine-weighted\n"
      "scrambled-Sobol rays over each vertex's (or texel's) hemisphere, against all scene geometry. Writes the\n"
      "scene again with per-vertex values as COLOR_0 or _AO (-o), and/or the raw values (--dump); or, with\n"
      "--texture SIZE, one occlusion texture per material (its occlusionTexture, a linear PNG).");
  cmd->add_option("scene", s.scene, "Input .gltf or .glb")->required();
  cmd->add_option("-o,--output", s.output,
                  "Output .gltf (+ .bin beside it) or .glb; everything but the baked attribute is kept as written");
  cmd->add_option("--dump", s.dump, "Raw values: .csv (node,mesh,primitive,vertex,x,y,z,ao) or .bin (float32)");
  add_tree(*cmd, bake_ao::request_tree(), s.options, s.given,
           {"Options", "Texture delivery (docs/delivery.md)", "Options"});
  add_dump_texture(*cmd, s.dump_texture, "", "Options");
  return cmd;
}

int run_bake_ao(const BakeAoSettings& s, const GlobalOptions& global) {
  bake_ao::Options options = s.options;
  options.output = s.output;
  options.dump = s.dump;
  if (Status st = finish_tree(bake_ao::request_tree(), options, s.given); !st) return report_error(st.error());
  if (Status st = set_dump_texture(options.ao, s.dump_texture, ""); !st) return report_error(st.error());
  auto report = bake_ao::bake_file(s.scene, options);
  if (!report) return report_error(report.error());
  nlohmann::json textures = nlohmann::json::array();
  for (const bake_ao::TextureReport& t : report->textures) textures.push_back(to_json(t));
  if (global.json) {
    std::cout << nlohmann::json{{"command", "bake-ao"}, {"scene", s.scene}, {"output", s.output}, {"dump", s.dump},
                                {"instances", report->instances}, {"vertices", report->vertices},
                                {"rays", report->rays}, {"seconds", report->seconds},
                                {"setup_seconds", report->setup_seconds}, {"ray_seconds", report->ray_seconds},
                                {"max_distance", report->max_distance}, {"mean_ao", report->mean},
                                {"texels", report->texels}, {"texel_seconds", report->texel_seconds},
                                {"textures", textures}, {"delivered", delivered_json(report->delivered)}, {"geometry", report->geometry}, {"notes", report->notes}}
                     .dump(2)
              << "\n";
  } else if (!global.quiet) {
    for (const std::string& note : report->geometry) std::cout << "geometry: " << escape_control(note) << "\n";
    for (const std::string& note : report->notes) std::cout << "note: " << escape_control(note) << "\n";
    print_texture_reports(report->textures);
    if (!report->textures.empty()) {
      std::printf("%s: %zu textures, %llu texels, %.3g rays in %.2f s (%.1f M rays/s; UV setup %.2f s), d_max %.4g, mean %.4f\n",
                  s.output.c_str(), report->textures.size(), (unsigned long long)report->texels, double(report->rays),
                  report->seconds, double(report->rays) / report->seconds / 1e6, report->texel_seconds,
                  report->max_distance, report->mean);
      return kOk;
    }
    std::printf("%s: %zu instances, %zu vertices, %.3g rays in %.2f s (%.1f M rays/s), d_max %.4g, mean %.4f\n",
                (s.output.empty() ? s.dump : s.output).c_str(), report->instances, report->vertices,
                double(report->rays), report->seconds, double(report->rays) / report->seconds / 1e6,
                report->max_distance, report->mean);
  }
  return kOk;
}

}  // namespace matbake::cli
