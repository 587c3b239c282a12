#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "matbake/ao.hpp"
#include "matbake/scene.hpp"

namespace matbake::cli {

CLI::App* setup_bake_ao(CLI::App& app, BakeAoSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "bake-ao",
      "Bake per-vertex ambient obscurance (ch. 12, eq. 12.72) of a glTF scene's triangles with Embree: cosine-\n"
      "weighted scrambled-Sobol rays over each vertex's hemisphere, against all scene geometry. Writes the\n"
      "scene again with the values as COLOR_0 or _AO (-o), and/or the raw values (--dump).");
  cmd->add_option("scene", s.scene, "Input .gltf or .glb")->required();
  cmd->add_option("-o,--output", s.output,
                  "Output .gltf (+ .bin beside it) or .glb; everything but the baked attribute is kept as written");
  cmd->add_option("--into", s.into, "COLOR_0 (multiplies the base colour in any viewer) or _AO (a float attribute)")
      ->capture_default_str();
  cmd->add_option("--existing-colors", s.existing_colors,
                  "With --into COLOR_0, a primitive's own COLOR_0: multiply (kept, times AO; alpha kept) or replace")
      ->capture_default_str();
  cmd->add_option("--dump", s.dump, "Raw values: .csv (node,mesh,primitive,vertex,x,y,z,ao) or .bin (float32)");
  cmd->add_option("--samples", s.options.samples, "Rays per vertex")->capture_default_str();
  cmd->add_option("--relative-distance", s.relative_distance, "d_max as a fraction of the scene radius")
      ->capture_default_str();
  cmd->add_option("--max-distance", s.absolute_distance, "d_max in scene units (instead of --relative-distance)");
  cmd->add_option("--tau", s.options.tau, "Falloff rate τ in units of 1/d_max")->capture_default_str();
  cmd->add_option("--falloff", s.falloff, "exponential (1 − e^(−τx), normalized to 1 at d_max) or none (binary AO)")
      ->capture_default_str();
  cmd->add_option("--bias", s.options.bias, "Ray-origin offset along the normal × the vertex's mean edge length")
      ->capture_default_str();
  cmd->add_flag("--two-sided", s.two_sided, "Surfaces seen from behind occlude too");
  cmd->add_flag("--fast-traversal", s.fast_traversal,
                "Embree's non-robust traversal: faster, but a ray may slip between triangles sharing an edge");
  cmd->add_option("--seed", s.options.seed, "Sample scrambling seed (same seed, same values, any --jobs)")
      ->capture_default_str();
  cmd->add_option("--sampler", s.sampler, "sobol or random")->capture_default_str();
  cmd->add_option("--recompute-normals", s.recompute_normals, "Replace the file's normals: equal, area or angle");
  return cmd;
}

int run_bake_ao(const BakeAoSettings& s, const GlobalOptions& global) {
  ao::Options options = s.options;
  if (s.falloff == "exponential") {
    options.falloff = ao::Falloff::exponential;
  } else if (s.falloff == "none") {
    options.falloff = ao::Falloff::none;
  } else {
    return report_error(Error{"", "--falloff '" + s.falloff + "': use exponential or none", true});
  }
  if (s.sampler == "sobol") {
    options.sampler = ao::Sampler::sobol;
  } else if (s.sampler == "random") {
    options.sampler = ao::Sampler::random;
  } else {
    return report_error(Error{"", "--sampler '" + s.sampler + "': use sobol or random", true});
  }
  if (s.output.empty() && s.dump.empty()) return report_error(Error{"", "bake-ao writes -o FILE, --dump FILE or both", true});
  if (const auto ext = std::filesystem::path(s.output).extension(); !s.output.empty() && ext != ".gltf" && ext != ".glb") {
    return report_error(Error{s.output, "the output is .gltf or .glb", true});
  }
  ao::Into into = ao::Into::attribute;
  if (s.into == "COLOR_0") {
    if (s.existing_colors != "multiply" && s.existing_colors != "replace") {
      return report_error(Error{"", "--existing-colors '" + s.existing_colors + "': use multiply or replace", true});
    }
    into = s.existing_colors == "multiply" ? ao::Into::color_multiply : ao::Into::color;
  } else if (s.into != "_AO") {
    return report_error(Error{"", "--into '" + s.into + "': use COLOR_0 or _AO", true});
  }
  options.two_sided = s.two_sided;
  options.watertight = !s.fast_traversal;
  options.relative_distance = s.absolute_distance <= 0;
  options.max_distance = options.relative_distance ? s.relative_distance : s.absolute_distance;

  auto scene = scene::load_scene(s.scene);
  if (!scene) return report_error(scene.error());
  if (!s.recompute_normals.empty()) {
    scene::NormalWeighting weighting;
    if (s.recompute_normals == "equal") {
      weighting = scene::NormalWeighting::equal;
    } else if (s.recompute_normals == "area") {
      weighting = scene::NormalWeighting::area;
    } else if (s.recompute_normals == "angle") {
      weighting = scene::NormalWeighting::angle;
    } else {
      return report_error(Error{"", "--recompute-normals '" + s.recompute_normals + "': use equal, area or angle", true});
    }
    for (scene::Instance& inst : scene->instances) {
      inst.normals = scene::vertex_normals(inst.positions, inst.triangles, weighting, inst.normals).normals;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  auto baked = ao::bake(*scene, options);
  if (!baked) return report_error(baked.error());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!s.dump.empty()) {
    if (Status st = ao::write_dump(s.dump, *scene, *baked); !st) return report_error(st.error());
  }
  if (!s.output.empty()) {
    if (Status st = ao::write_gltf(s.scene, *scene, *baked, into, s.output); !st) return report_error(st.error());
  }

  std::size_t vertices = 0;
  double sum = 0;
  for (const auto& values : baked->values) {
    vertices += values.size();
    for (float w : values) sum += w;
  }
  if (global.json) {
    std::cout << nlohmann::json{{"command", "bake-ao"}, {"scene", s.scene}, {"output", s.output}, {"dump", s.dump},
                                {"instances", scene->instances.size()}, {"vertices", vertices},
                                {"rays", baked->rays}, {"seconds", seconds}, {"max_distance", baked->max_distance},
                                {"mean_ao", vertices ? sum / double(vertices) : 0.0}, {"notes", scene->notes}}
                     .dump(2)
              << "\n";
  } else if (!global.quiet) {
    for (const std::string& note : scene->notes) std::cout << "note: " << note << "\n";
    std::printf("%s: %zu instances, %zu vertices, %.3g rays in %.2f s (%.1f M rays/s), d_max %.4g, mean %.4f\n",
                (s.output.empty() ? s.dump : s.output).c_str(), scene->instances.size(), vertices, double(baked->rays), seconds,
                double(baked->rays) / seconds / 1e6, baked->max_distance, vertices ? sum / double(vertices) : 0.0);
  }
  return kOk;
}

}  // namespace matbake::cli
