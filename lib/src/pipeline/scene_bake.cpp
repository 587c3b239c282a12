#include "scene_bake.hpp"

#include <algorithm>
#include <set>
#include <system_error>

#include "matbake/output_check.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;

std::vector<fs::path> bake_folders(const fs::path& state_folder, const Job& job) {
  const fs::path work = state_folder / "bake" / job_file_stem(job.name);
  return {work.parent_path(), work, work / "kept"};
}

namespace {

// A file a bake writes in its work folder (the baked glTF, its maps: EXR or PNG) or in kept/ (maps.json and
// "N_map.f32").
bool made_by_a_bake(const fs::path& file, bool kept) {
  const std::string name = file.filename().string(), extension = file.extension().string();
  if (!kept) return extension == ".glb" || extension == ".gltf" || extension == ".bin" || extension == ".exr" || extension == ".png";
  const std::size_t underscore = name.find('_');
  const bool numbered = underscore > 0 && underscore != std::string::npos &&
                        std::all_of(name.begin(), name.begin() + std::ptrdiff_t(underscore), [](char c) { return c >= '0' && c <= '9'; });
  return name == "maps.json" || (numbered && extension == ".f32");
}

// Removes `folder`'s regular files a bake makes (not following links), and the folder when empty.
void empty_bake_folder(const fs::path& folder, bool kept) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
    if (entry.symlink_status(ec).type() == fs::file_type::regular && made_by_a_bake(entry.path(), kept)) fs::remove(entry.path(), ec);
  }
  fs::remove(folder, ec);  // only when empty
}

}  // namespace

std::vector<fs::path> remove_stale_bakes(const Plan& plan, const Manifest& manifest) {
  std::set<fs::path> baking;
  for (const Job& job : plan.jobs) {
    if (job.kind == JobKind::scene && manifest.scenes[job.spec].bake) baking.insert(bake_folders(plan.state_folder, job)[1]);
  }
  std::vector<fs::path> removed;
  std::error_code ec;
  // Not through a link (make_plan checks it only when a scene bakes).
  if (fs::symlink_status(plan.state_folder / "bake", ec).type() != fs::file_type::directory) return removed;
  for (const fs::directory_entry& entry : fs::directory_iterator(plan.state_folder / "bake", ec)) {
    const fs::path work = entry.path();
    if (baking.count(work) || entry.symlink_status(ec).type() != fs::file_type::directory) continue;
    if (fs::symlink_status(work / "kept", ec).type() == fs::file_type::directory) empty_bake_folder(work / "kept", true);
    empty_bake_folder(work, false);
    if (!fs::exists(fs::symlink_status(work, ec))) removed.push_back(work);
  }
  return removed;
}

Result<BakedScene> bake_scene(const Job& job, const SceneSpec& s, const fs::path& state_folder, const image::Encoding& encoding) {
  const std::vector<fs::path> folders = bake_folders(state_folder, job);
  const fs::path& work = folders[1];
  std::error_code ec;
  fs::create_directories(work, ec);
  if (ec) return Error{work.string(), "cannot make the bake's folder: " + ec.message()};
  // Named as the scene's output, so that the float maps are named as `matbake bake` names them.
  BakedScene baked{work / (job.outputs.scene.stem().string() + ".glb"), {}};
  // The maps are kept there too: a change to some parameters re-traces only the maps they decide.
  bake::FileOptions options{s.bake->high, s.bake->cage, baked.gltf, s.bake->request, encoding, folders[2]};
  auto report = bake::bake_file(s.input, options);
  if (!report) return Error{s.origins.of("bake"), "scenes." + s.name + ".bake: " + report.error().to_string()};
  baked.report = std::move(*report);
  return baked;
}

Status check_baked_materials(const SceneSpec& s, const BakedScene& baked, const std::vector<exporter::MaterialMaps>& given) {
  const auto& maps = s.bake->request.bake.maps;
  const auto asks = [&](bake::Map m) { return std::find(maps.begin(), maps.end(), m) != maps.end(); };
  for (const bake::TextureReport& t : baked.report.textures) {
    for (const exporter::MaterialMaps& g : given) {
      if (g.material != t.name && g.material != t.copy_of) continue;
      // Without occlusion of its own, the manifest material's metal-rough maps keep the baked
      // occlusionTexture (export packs them into one ORM).
      const char* lost = asks(bake::Map::transfer)                                  ? "transfer"
                         : asks(bake::Map::ao) && g.maps.find(material::kOcclusion)   ? "ao"
                         : asks(bake::Map::normal) && g.maps.find(material::kNormal) ? "normal"
                                                                                     : nullptr;
      if (!lost) continue;
      return Error{s.origins.of("bake"), "scenes." + s.name + ": glTF material '" + t.name +
                                             "' is baked and also given a manifest material, whose maps would replace the "
                                             "baked " + lost + " map; bake it onto a material the manifest does not give, "
                                             "or drop " + lost + " from bake.maps"};
    }
  }
  return success();
}

Result<std::vector<fs::path>> baked_map_targets(const Job& job, const BakedScene& baked, const OutputGate& gate) {
  std::vector<NamedOutput> named;
  std::vector<fs::path> targets;
  for (const std::string& file : baked.report.beside) {
    const fs::path target = job.outputs.scene.parent_path() / fs::path(file).filename();
    if (!gate.holds(target)) {
      return Error{target.string(), "the baked map would be written outside the output folder (through a link); matbake writes only inside it"};
    }
    if (gate.is_protected(target)) {
      return Error{target.string(), "the baked map is named as an input or another output of this build; matbake never "
                                    "overwrites either (rename the scene's output or the glTF material)"};
    }
    targets.push_back(target);
    named.push_back({target, "baked map"});
  }
  if (Status s = check_outputs(named, {}); !s) return s.error();  // two maps of one name
  return targets;
}

Result<std::vector<fs::path>> finish_bake(const BakedScene& baked, std::vector<fs::path> targets, const OutputGate& gate) {
  for (std::size_t i = 0; i < targets.size() && i < baked.report.beside.size(); ++i) {
    std::error_code ec;
    fs::rename(baked.report.beside[i], targets[i], ec);
    if (ec) return Error{targets[i].string(), "cannot move the baked map here: " + ec.message()};
  }
  for (const std::string& file : baked.report.written) {
    const bool moved = std::find(baked.report.beside.begin(), baked.report.beside.end(), file) != baked.report.beside.end();
    std::error_code ec;
    if (!moved && gate.holds(file) && !gate.is_protected(file)) fs::remove(file, ec);
  }
  return targets;
}

}  // namespace matbake::pipeline
