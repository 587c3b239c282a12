#include "vertices.hpp"

#include <chrono>

#include "../delivery/deliver.hpp"
#include "../delivery/geometry.hpp"
#include "../gltf/decode.hpp"
#include "../gltf/vertex_occlusion.hpp"
#include "textures.hpp"
#include "../scene/from_document.hpp"
#include "matbake/bake_ao.hpp"
#include "matbake/output_check.hpp"

namespace matbake::bake_ao {
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
Status check_outputs(const gltf::Document& doc, const Options& options, const std::vector<fs::path>& textures) {
  std::vector<NamedOutput> outputs = {{options.output, "glTF output"}, {options.dump, "dump"}};
  for (const fs::path& t : textures) outputs.push_back({t, "texture dump"});
  return check_outputs(outputs, gltf::source_files(doc.file, doc.json));
}

double mean_of(const std::vector<std::vector<float>>& values, std::size_t& count) {
  double sum = 0;
  for (const auto& v : values) {
    count += v.size();
    for (float w : v) sum += w;
  }
  return count ? sum / double(count) : 0.0;
}

}  // namespace

Result<ao::Bake> bake_into(gltf::Document& doc, const scene::Scene& scene, const ao::Request& request) {
  auto baked = ao::bake(scene, request.options);
  if (!baked) return baked.error();
  const std::vector<gltf::PlacedValues> placed = placed_values(scene, *baked);
  gltf::add_vertex_occlusion(doc, placed, request.into);
  return baked;
}

Result<Report> bake_file(const fs::path& input, const Options& options) {
  return guarded(input.string(), [&]() -> Result<Report> {
    if (options.output.empty() && options.dump.empty()) return Error{"", "bake-ao writes a glTF, a dump or both", true};
    if (const fs::path ext = options.output.extension(); !options.output.empty() && ext != ".gltf" && ext != ".glb") {
      return Error{options.output.string(), "the output is .gltf or .glb", true};
    }
    if (const fs::path ext = options.dump.extension(); !options.dump.empty() && ext != ".csv" && ext != ".bin") {
      return Error{options.dump.string(), "the dump is .csv or .bin", true};
    }
    if (Status s = ao::check(options.ao.options); !s) return s.error();
    const std::optional<ao::TextureRequest>& texture = options.ao.texture;
    if (texture) {
      if (Status s = ao::check(*texture, options.ao.options); !s) return s.error();
      if (!options.dump.empty()) return Error{options.dump.string(), mention("dump") + " holds per-vertex values; with " + mention("texture") + " use " + mention("dump_texture"), true};
      if (options.output.empty()) return Error{"", "a texture bake writes a glTF (-o)", true};
    }
    // Read once: the scene to bake and the document the values go into.
    auto doc = gltf::read_document(input);
    if (!doc) return doc.error();
    auto scene = scene::scene_from_document(*doc, {.texcoords = bool(texture)});
    if (!scene) return scene.error();
    const std::string stem = options.output.stem().string();
    OcclusionTargets targets;
    std::vector<fs::path> dumped;
    if (texture) {
      auto found = occlusion_targets(*doc, *scene, *texture);
      if (!found) return found.error();
      targets = std::move(*found);
      for (int m : targets.materials) {
        if (!texture->dump.empty()) dumped.push_back(dumped_texture(texture->dump, stem, m));
      }
    }
    if (Status s = check_outputs(*doc, options, dumped); !s) return s.error();

    Report report;
    report.notes = scene->notes;
    report.instances = scene->instances.size();
    const auto start = std::chrono::steady_clock::now();
    if (texture) {
      ao::TextureBakes timing;
      gltf::ImageCache cache(*doc, options.encoding, delivery::made_format(options.delivery));
      auto textures = bake_occlusion_textures(*doc, *scene, cache, options.ao, targets, stem, OcclusionInto::texture, timing);
      if (!textures) return textures.error();
      report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      report.textures = std::move(*textures);
      report.notes.insert(report.notes.end(), targets.notes.begin(), targets.notes.end());
      report.rays = timing.rays;
      report.setup_seconds = timing.setup_seconds;
      report.texel_seconds = timing.texel_seconds;
      report.ray_seconds = timing.ray_seconds;
      report.max_distance = timing.max_distance;
      double sum = 0;
      for (const TextureReport& t : report.textures) {
        report.texels += t.covered + t.touched;
        sum += t.mean * double(t.covered + t.touched);
      }
      report.mean = report.texels ? sum / double(report.texels) : 0.0;
      for (const fs::path& p : dumped) report.written.push_back(p.string());
    } else {
      auto baked = ao::bake(*scene, options.ao.options);
      if (!baked) return baked.error();
      report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!options.dump.empty()) {
        if (Status s = ao::write_dump(options.dump, *scene, *baked); !s) return s.error();
        report.written.push_back(options.dump.string());
      }
      if (!options.output.empty()) {
        const std::vector<gltf::PlacedValues> placed = placed_values(*scene, *baked);
        gltf::add_vertex_occlusion(*doc, placed, options.ao.into);
      }
      report.mean = mean_of(baked->values, report.vertices);
      report.rays = baked->rays;
      report.setup_seconds = baked->setup_seconds;
      report.ray_seconds = baked->ray_seconds;
      report.max_distance = baked->max_distance;
    }
    report.geometry = gltf::geometry_notes(*doc);
    if (!options.output.empty() && delivery::changes_textures(options.delivery)) {
      gltf::ImageCache cache(*doc, options.encoding, delivery::made_format(options.delivery));
      auto delivered = delivery::deliver_textures(*doc, cache, options.delivery, options.output);
      if (!delivered) return delivered.error();
      report.delivered = std::move(*delivered);
      (void)delivery::store_once(*doc, report.delivered);  // the images KTX2 or resized ones replaced
    }
    if (!options.output.empty() && options.delivery.geometry.any()) {
      auto geometry = delivery::deliver_geometry(*doc, options.delivery.geometry);
      if (!geometry) return geometry.error();
      report.geometry = std::move(*geometry);
    }
    if (!options.output.empty()) {
      auto written = gltf::write_document(*doc, options.output);
      if (!written) return written.error();
      for (const fs::path& p : *written) report.written.push_back(p.string());
    }
    return report;
  });
}

}  // namespace matbake::bake_ao
