#include <nlohmann/json.hpp>

#include <cstdio>

#include "commands.hpp"
#include "matbake/bake_params.hpp"
#include "matbake/report_json.hpp"
#include "params_cli.hpp"

namespace matbake::cli {

CLI::App* setup_bake(CLI::App& app, BakeSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "bake",
      "Bake a high-poly mesh onto a low-poly one's UVs (docs/bake.md): per texel, rays from a cage around the\n"
      "low-poly along its normal find the high-poly; its normal in the low-poly's tangent basis (the TANGENT\n"
      "written, MikkTSpace where the file has none) becomes the material's normalTexture, AO its\n"
      "occlusionTexture; the other maps are written as float EXR files beside the output. --vertex-maps\n"
      "bakes AO, thickness, curvature or height per low-poly vertex into attributes instead (_AO or COLOR_0, ...).");
  cmd->add_option("low", s.low, "The low-poly .gltf or .glb (its UVs take the maps)")->required();
  cmd->add_option("--from", s.high, "The high-poly .gltf or .glb")->required();
  cmd->add_option("--cage", s.cage,
                  "A cage mesh (.gltf or .glb): the low-poly with its vertices moved out; rays start on it and head "
                  "for the low-poly (--front only where it touches the low-poly)");
  cmd->add_option("-o,--output", s.output, "Output .gltf (+ .bin beside it) or .glb")->required();
  add_tree(*cmd, bake::request_tree(), s.options, s.given, {"Options", "Options", "AO and bent normal (rays from the high-poly's hit)"});
  return cmd;
}

int run_bake(const BakeSettings& s, const GlobalOptions& global) {
  bake::FileOptions options = s.options;
  options.high = s.high;
  options.cage = s.cage;
  options.output = s.output;
  if (Status st = finish_tree(bake::request_tree(), options, s.given); !st) return report_error(st.error());
  auto report = bake::bake_file(s.low, options);
  if (!report) return report_error(report.error());
  for (const std::string& w : report->warnings) std::cerr << "matbake: warning: " << escape_control(w) << "\n";
  if (global.json) {
    nlohmann::json out = {{"command", "bake"}, {"low", s.low}, {"high", s.high}, {"output", s.output}};
    if (!s.cage.empty()) out["cage"] = s.cage;
    out.update(to_json(*report));
    std::cout << out.dump(2) << "\n";
  } else if (!global.quiet) {
    for (const std::string& note : report->notes) std::cout << "note: " << escape_control(note) << "\n";
    for (const bake::TextureReport& t : report->textures) {
      const std::string tile = t.tile ? " tile " + std::to_string(t.tile) : "";
      std::printf("  material %d %s%s: %dx%d, %zu texels, %zu rays, %zu missed (%zu texels filled)", t.material,
                  escape_control(t.name).c_str(), tile.c_str(), t.width, t.height, t.texels, t.samples, t.misses, t.missed_texels);
      if (t.height_max > t.height_min) std::printf(", height %.4g to %.4g", t.height_min, t.height_max);
      std::printf("\n");
      for (std::size_t i = 0; i < t.files.size() && i < t.ranges.size(); ++i) {  // PNG maps beside: what 0 and 1 stand for
        if (!t.ranges[i]) continue;
        const auto [lo, hi] = *t.ranges[i];
        if (lo != 0 || hi != 1) {
          std::printf("    %s: 0 to 1 is %.6g to %.6g\n", escape_control(t.files[i]).c_str(), lo, hi);
        }
      }
    }
    if (!report->vertices.attributes.empty()) {
      std::string attributes;
      for (const std::string& a : report->vertices.attributes) attributes += (attributes.empty() ? "" : ", ") + a;
      std::printf("  vertices: %zu, %zu missed%s, written as %s\n", report->vertices.vertices, report->vertices.misses,
                  report->vertices.misses ? " (each filled from its neighbours)" : "", attributes.c_str());
    }
    std::printf("%s: %zu textures, cage %.4g out / %.4g in, tangents on %zu primitives (%zu vertices split), %.2f s "
                "(trace %.2f s)\n",
                s.output.c_str(), report->textures.size(), report->front, report->back, report->tangent_primitives,
                report->split_vertices, report->seconds, report->trace_seconds);
  }
  return kOk;
}

}  // namespace matbake::cli
