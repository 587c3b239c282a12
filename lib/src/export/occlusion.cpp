#include "occlusion.hpp"

#include <chrono>

#include "../gltf/vertex_occlusion.hpp"
#include "../scene/from_document.hpp"
#include "matbake/export.hpp"
#include "matbake/output_check.hpp"

namespace matbake::exporter {
namespace fs = std::filesystem;
namespace {

std::vector<gltf::PlacedValues> placed_values(const scene::Scene& scene, const ao::Bake& baked) {
  std::vector<gltf::PlacedValues> placed;
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const scene::Instance& inst = scene.instances[k];
    placed.push_back({inst.node, inst.primitive, baked.values[k], inst.colors, inst.colors_have_alpha});
  }
  return placed;
}

// An output onto a file the scene is read from, or two outputs onto one file, is refused before
// any work.
Status check_outputs(const gltf::Document& doc, const BakeAoOptions& options) {
  const NamedOutput outputs[] = {{options.output, "glTF output"}, {options.dump, "dump"}};
  return check_outputs(outputs, gltf::source_files(doc.file, doc.json));
}

}  // namespace

Result<ao::Bake> bake_into(gltf::Document& doc, const scene::Scene& scene, const ao::Request& request) {
  auto baked = ao::bake(scene, request.options);
  if (!baked) return baked.error();
  const std::vector<gltf::PlacedValues> placed = placed_values(scene, *baked);
  gltf::add_vertex_occlusion(doc, placed, request.into);
  return baked;
}

Result<BakeAoReport> bake_ao_file(const fs::path& input, const BakeAoOptions& options) {
  return guarded(input.string(), [&]() -> Result<BakeAoReport> {
    if (options.output.empty() && options.dump.empty()) return Error{"", "bake-ao writes a glTF, a dump or both", true};
    if (const fs::path ext = options.output.extension(); !options.output.empty() && ext != ".gltf" && ext != ".glb") {
      return Error{options.output.string(), "the output is .gltf or .glb", true};
    }
    if (const fs::path ext = options.dump.extension(); !options.dump.empty() && ext != ".csv" && ext != ".bin") {
      return Error{options.dump.string(), "the dump is .csv or .bin", true};
    }
    if (Status s = ao::check(options.ao.options); !s) return s.error();
    // Read once: the scene to bake and the document the values go into.
    auto doc = gltf::read_document(input);
    if (!doc) return doc.error();
    if (Status s = check_outputs(*doc, options); !s) return s.error();
    auto scene = scene::scene_from_document(*doc);
    if (!scene) return scene.error();

    const auto start = std::chrono::steady_clock::now();
    auto baked = ao::bake(*scene, options.ao.options);
    if (!baked) return baked.error();
    BakeAoReport report;
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!options.dump.empty()) {
      if (Status s = ao::write_dump(options.dump, *scene, *baked); !s) return s.error();
      report.written.push_back(options.dump.string());
    }
    if (!options.output.empty()) {
      const std::vector<gltf::PlacedValues> placed = placed_values(*scene, *baked);
      gltf::add_vertex_occlusion(*doc, placed, options.ao.into);
      auto written = gltf::write_document(*doc, options.output);
      if (!written) return written.error();
      for (const fs::path& p : *written) report.written.push_back(p.string());
    }
    double sum = 0;
    for (const auto& values : baked->values) {
      report.vertices += values.size();
      for (float w : values) sum += w;
    }
    report.instances = scene->instances.size();
    report.rays = baked->rays;
    report.setup_seconds = baked->setup_seconds;
    report.ray_seconds = baked->ray_seconds;
    report.max_distance = baked->max_distance;
    report.mean = report.vertices ? sum / double(report.vertices) : 0.0;
    report.notes = scene->notes;
    return report;
  });
}

}  // namespace matbake::exporter
