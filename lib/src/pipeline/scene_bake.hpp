#pragma once
// A manifest scene's bake (`bake = { from, maps, ... }`, docs/build.md#baking): the high-poly's maps
// baked onto the scene's glTF in the state folder, which the export then reads; the float maps the
// glTF does not reference are moved beside the scene's output once the export has succeeded.
#include <filesystem>
#include <vector>

#include "matbake/bake_file.hpp"
#include "matbake/export.hpp"
#include "matbake/output_gate.hpp"
#include "matbake/pipeline.hpp"

namespace matbake::pipeline {

struct BakedScene {
  std::filesystem::path gltf;  // the bake's output, OUT/.matbake/bake/<job>/<scene stem>.glb: the export's input
  bake::FileReport report;
};

// The folders a scene job's bake writes in and empties: OUT/.matbake/bake, its own folder there
// (BakedScene::gltf's) and its kept maps', outermost first. make_plan checks each is no link out of
// the output folder.
std::vector<std::filesystem::path> bake_folders(const std::filesystem::path& state_folder, const Job& job);

// After a full build: the work folders under OUT/.matbake/bake of scenes that bake no longer
// (removed, renamed, their bake dropped) emptied of what a bake leaves there (its kept maps and
// their index; a failed bake's glTF and maps), then removed when empty. A link is never followed,
// and a file of another name is left, with its folder. Returns the folders removed.
std::vector<std::filesystem::path> remove_stale_bakes(const Plan& plan, const Manifest& manifest);

Result<BakedScene> bake_scene(const Job& job, const SceneSpec& s, const std::filesystem::path& state_folder,
                              const image::Encoding& encoding);

// A baked material that the manifest also gives a material: its maps would replace the baked ones
// (base colour always, the occlusion and normal map when it has them), which is refused, naming both.
Status check_baked_materials(const SceneSpec& s, const BakedScene& baked, const std::vector<exporter::MaterialMaps>& given);

// Where the float maps go, beside the scene's output, checked by `gate` (the plan's: its inputs and
// every job's outputs protected) before the export writes anything: only inside the output folder's
// real path, never onto a file the build reads or another job writes (a map's name comes from the
// glTF's material, which the plan cannot know).
Result<std::vector<std::filesystem::path>> baked_map_targets(const Job& job, const BakedScene& baked, const OutputGate& gate);

// After the export: the float maps moved to `targets` (baked_map_targets'), the rest of the bake's
// work removed (only what the bake wrote, inside the output folder). Returns the maps as moved.
Result<std::vector<std::filesystem::path>> finish_bake(const BakedScene& baked, std::vector<std::filesystem::path> targets,
                                                       const OutputGate& gate);

}  // namespace matbake::pipeline
