// `matbake inspect MANIFEST`: each job's state as a build would find it (its stamp, the failure
// recorded beside it), what it reads and would write. Nothing is built or written.
#include "matbake/bake.hpp"
#include "matbake/inspect.hpp"
#include "matbake/join.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/report_json.hpp"

namespace matbake::inspect {
namespace fs = std::filesystem;
namespace {

nlohmann::json paths(const std::vector<fs::path>& files) {
  nlohmann::json out = nlohmann::json::array();
  for (const fs::path& f : files) out.push_back(f.string());
  return out;
}

// up_to_date, out_of_date (with why and the parameters changed), or failed (its last run's error line,
// or the problem planning found).
nlohmann::json state_of(const pipeline::JobReport& r, const pipeline::JobStatus* status) {
  if (r.outcome == pipeline::Outcome::failed && r.error) return {{"state", "failed"}, {"error", r.error->to_string()}};
  if (status && status->state == pipeline::JobState::failed) return {{"state", "failed"}, {"error", status->detail}};
  if (r.outcome == pipeline::Outcome::up_to_date) return {{"state", "up_to_date"}};
  nlohmann::json out = {{"state", "out_of_date"}, {"reason", r.reason}};
  if (!r.changed.is_null()) out["changed"] = r.changed;
  return out;
}

// A scene's delivery as planned: each texture's class, sizes (the texel density's needed side when
// set), codec, levels and estimated bytes, and the estimated bytes per class; or why it cannot be planned.
nlohmann::json planned_delivery(const pipeline::Manifest& manifest, const pipeline::Job& job) {
  auto planned = pipeline::plan_scene(manifest, job);
  if (!planned) return {{"error", planned.error().to_string()}};
  nlohmann::json textures = nlohmann::json::array();
  std::map<std::string, std::uint64_t> by_class{{"colour", 0}, {"data", 0}, {"normal", 0}, {"total", 0}};
  for (const delivery::TextureReport& t : *planned) {
    nlohmann::json entry = to_json(t);
    entry.erase("file");
    entry.erase("bytes");
    entry["estimated_bytes"] = t.bytes;
    textures.push_back(std::move(entry));
    by_class[std::string(name_in(delivery::kTextureClassNames, t.texture_class))] += t.bytes;
    by_class["total"] += t.bytes;
  }
  nlohmann::json out = {{"textures", textures}, {"estimated_bytes", by_class}};
  // The plan exports the scene as it is: the textures its bake adds exist only once it has traced.
  if (const auto& bake = manifest.scenes[job.spec].bake; bake && !bake->request.bake.maps.empty()) {
    std::vector<std::string> maps;
    for (bake::Map m : bake->request.bake.maps) maps.emplace_back(name_in(bake::kMapNames, m));
    const ao::TextureOptions& t = bake->request.texture;
    out["not_estimated"] = "the bake's maps (" + join(maps, ", ") + ", " + std::to_string(t.width) + "x" + std::to_string(t.height) +
                           " a baked material): made when the scene is built, not in this estimate";
  }
  return out;
}

}  // namespace

Result<nlohmann::json> inspect_manifest(const fs::path& path) {
  auto manifest = pipeline::read_manifest(path);
  if (!manifest) return manifest.error();
  auto plan = pipeline::make_plan(*manifest);
  if (!plan) return plan.error();
  pipeline::RunOptions dry;
  dry.dry_run = true;
  auto report = pipeline::run(*manifest, *plan, dry);
  if (!report) return report.error();
  auto statuses = pipeline::job_statuses(*manifest, *plan);
  if (!statuses) return statuses.error();

  nlohmann::json jobs = nlohmann::json::array();
  std::map<std::string, std::size_t> counts;
  for (std::size_t i = 0; i < report->jobs.size(); ++i) {
    const pipeline::JobReport& r = report->jobs[i];
    const pipeline::Job& job = *r.job;
    nlohmann::json entry = {{"name", job.name},
                            {"kind", job.kind == pipeline::JobKind::material ? "material" : "scene"},
                            {"inputs", paths(job.inputs)},
                            {"outputs", paths(job.outputs.all())},
                            {"depends_on", job.depends_on}};
    entry.update(state_of(r, i < statuses->size() ? &(*statuses)[i] : nullptr));
    ++counts[entry["state"].get<std::string>()];
    if (job.kind == pipeline::JobKind::scene) {
      nlohmann::json materials = nlohmann::json::object();
      for (const auto& [gltf_name, m] : job.materials) materials[gltf_name] = manifest->materials[m].name;
      entry["materials"] = materials;
      entry["delivery"] = planned_delivery(*manifest, job);
    }
    jobs.push_back(std::move(entry));
  }
  nlohmann::json count_json = nlohmann::json::object();
  for (const char* state : {"up_to_date", "out_of_date", "failed"}) count_json[state] = counts[state];
  return nlohmann::json{{"kind", "manifest"},
                        {"file", manifest->file.string()},
                        {"output", manifest->output.string()},
                        {"jobs", jobs},
                        {"counts", count_json},
                        {"warnings", plan->warnings}};
}

}  // namespace matbake::inspect
