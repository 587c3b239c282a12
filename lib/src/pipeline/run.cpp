// Running a plan: the out-of-date jobs in parallel, each source file decoded once and freed when
// the last job that reads it is done.
#include <tbb/parallel_for_each.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <set>

#include "matbake/atomic_file.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/material_table.hpp"
#include "matbake/report_json.hpp"
#include "matbake/validate.hpp"
#include "matbake/workflow_maps.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

// Decoded source files shared by the jobs of one run. Each file is decoded once per transfer; it is
// freed when every job that declared it has released it, so memory follows the jobs in flight, not
// the size of the manifest.
class DecodeCache {
 public:
  explicit DecodeCache(const std::map<fs::path, std::size_t>& uses) {
    for (const auto& [path, n] : uses) entries_[path] = std::make_unique<Entry>(n);
  }

  Result<std::shared_ptr<const image::Image>> read(const fs::path& file, color::Transfer transfer) {
    const fs::path key = fs::absolute(file).lexically_normal();
    Entry* entry = nullptr;
    {
      std::lock_guard lock(mutex_);
      auto& e = entries_[key];
      if (!e) e = std::make_unique<Entry>(0);  // not declared: decoded, kept until the run ends
      entry = e.get();
    }
    std::lock_guard lock(entry->mutex);  // a second reader of the same file waits for the first decode
    if (const auto found = entry->images.find(transfer); found != entry->images.end()) return found->second;
    auto decoded = image::read_image(file, transfer);
    if (!decoded) return decoded.error();
    ++decoded_;
    auto shared = std::make_shared<const image::Image>(std::move(*decoded));
    entry->images[transfer] = shared;
    return shared;
  }

  void release(const fs::path& file) {
    std::lock_guard lock(mutex_);
    const auto found = entries_.find(file);
    if (found == entries_.end() || found->second->uses == 0) return;
    if (--found->second->uses == 0) {
      std::lock_guard entry_lock(found->second->mutex);
      found->second->images.clear();
    }
  }

  std::size_t decoded() const { return decoded_; }

 private:
  struct Entry {
    explicit Entry(std::size_t n) : uses(n) {}
    std::mutex mutex;
    std::map<color::Transfer, std::shared_ptr<const image::Image>> images;
    std::size_t uses;
  };
  std::mutex mutex_;
  std::map<fs::path, std::unique_ptr<Entry>> entries_;
  std::atomic<std::size_t> decoded_{0};
};

// The image files a material decodes.
std::vector<fs::path> decoded_files(const MaterialSpec& m) {
  std::vector<fs::path> files;
  for (const pack::SourceInput& s : m.sources) {
    if (!s.file.empty()) files.push_back(fs::absolute(s.file).lexically_normal());
  }
  for (const fs::path& f : m.packed_files) files.push_back(fs::absolute(f).lexically_normal());
  std::sort(files.begin(), files.end());
  files.erase(std::unique(files.begin(), files.end()), files.end());
  return files;
}

std::vector<fs::path> decoded_files(const Job& job, const Manifest& manifest) {
  if (job.kind == JobKind::material) return decoded_files(manifest.materials[job.spec]);
  std::set<fs::path> files;
  for (const auto& [gltf_name, m] : job.materials) {
    for (const fs::path& f : decoded_files(manifest.materials[m])) files.insert(f);
  }
  return {files.begin(), files.end()};
}

// An error loading a material's maps, placed at the manifest value it comes from: the source whose
// file it names, else the material's table.
Error at_source(const MaterialSpec& m, const Error& e) {
  std::string key;
  for (const pack::SourceInput& s : m.sources) {
    if (!s.file.empty() && s.file.string() == e.path) key = "sources." + s.name;
  }
  for (const fs::path& f : m.packed_files) {
    if (f.string() == e.path) key = "packed.files";
  }
  return Error{m.origins.of(key), "materials." + m.name + ": " + e.to_string()};
}

Result<material::Maps> load_material(const MaterialSpec& m, DecodeCache& cache) {
  const pack::ImageReader read = [&cache](const fs::path& f, color::Transfer t) { return cache.read(f, t); };
  auto maps = pack::load_material(m.sources, m.packed ? &m.packed->layout : nullptr, m.packed_files, m.options, read);
  if (!maps) return at_source(m, maps.error());
  return maps;
}

struct JobContext {
  const Manifest& manifest;
  DecodeCache& cache;
  const std::vector<material_table::Material>* table;  // null when it could not be read
  const Error* table_error;
};

Status ensure_folder(const fs::path& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) return Error{folder.string(), "cannot make the output folder: " + ec.message()};
  return success();
}

// Validation of the material as authored; a job error when more texels are flagged than allowed.
Status validate_material(const MaterialSpec& m, const material::Maps& maps, const JobContext& ctx,
                         const JobOutputs& outputs, JobReport& report) {
  validate::Options options = m.validation.options;
  options.class_map = m.validation.heatmap;
  if (!m.reference.empty()) {
    if (!ctx.table) return *ctx.table_error;
    auto material = material_table::lookup(*ctx.table, m.reference);
    if (!material) return Error{m.origins.of("reference"), "materials." + m.name + ".reference: " + material.error().message};
    options.material = *material;
  }
  auto result = validate::validate_maps(maps, options);
  if (!result) {
    return Error{m.origins.of(""), "materials." + m.name + ": " + result.error().message +
                                                 "; set validate = { enabled = false } to skip it"};
  }
  const bool passed = validate::passed(*result, options);
  report.details["validation"] = {{"checked", result->checked},
                                  {"violations", result->violations},
                                  {"violation_fraction", result->violation_fraction()},
                                  {"passed", passed}};
  const fs::path& json_file = outputs.validation_report;
  report.details["validation"]["report"] = json_file.string();
  if (Status s = write_validation_report(*result, options, json_file); !s) return s;
  if (m.validation.heatmap) {
    if (Status s = validate::write_heatmap(*result, outputs.heatmap); !s) return s;
  }
  char line[160];
  std::snprintf(line, sizeof line, "validation: %zu of %zu texels flagged (%.3g%%; max_violations %.3g%%)",
                result->violations, result->checked, 100 * result->violation_fraction(), 100 * options.max_violations);
  // The failure is the material's (or its max_violations', when it sets one); the report says which texels.
  if (!passed) {
    return Error{m.origins.of("validate.max_violations"),
                 "materials." + m.name + ": " + line + "; the texels are in " + json_file.string()};
  }
  if (result->violations) report.warnings.push_back(line);
  return success();
}

Status run_material(const Job& job, const JobContext& ctx, JobReport& report) {
  return guarded(ctx.manifest.materials[job.spec].name, [&]() -> Status {
    const MaterialSpec& m = ctx.manifest.materials[job.spec];
    auto maps = load_material(m, ctx.cache);
    if (!maps) return maps.error();
    report.details["size"] = {maps->width, maps->height};
    if (Status s = ensure_folder(ctx.manifest.output / "materials"); !s) return s;
    if (m.layout) {
      const pack::Layout* layout = &m.layout->layout;
      // Validation reads the maps as loaded: the workflow gets a copy only when it converts them
      // (else it hands them back, and validation reads them there).
      const bool converts = workflow::layout_direction(*maps, *layout).has_value();
      auto in_workflow = workflow::in_layout_workflow(converts ? material::Maps(*maps) : std::move(*maps), *layout, m.options.mapping);
      if (!in_workflow) {
        return Error{m.origins.of("layout"), "materials." + m.name + ".layout: " + in_workflow.error().to_string()};
      }
      if (!converts) *maps = std::move(in_workflow->maps);
      if (converts) report.details["conversion"] = to_json(*in_workflow, m.options.mapping);
      const std::vector<std::string> outputs(job.outputs.textures.begin(), job.outputs.textures.end());
      auto written = pack::write_textures(*layout, converts ? in_workflow->maps : *maps,
                                          {outputs, m.options.bits, m.options.transfer, decoded_files(m), {}, m.encoding});
      if (!written) return written.error();
    }
    if (m.validation.enabled) return validate_material(m, *maps, ctx, job.outputs, report);
    return success();
  });
}

Result<std::vector<fs::path>> run_scene(const Job& job, const JobContext& ctx, JobReport& report) {
  return guarded(ctx.manifest.scenes[job.spec].input.string(), [&]() -> Result<std::vector<fs::path>> {
    const SceneSpec& s = ctx.manifest.scenes[job.spec];
    exporter::Options options = s.options;
    for (const auto& [gltf_name, m] : job.materials) {
      const MaterialSpec& spec = ctx.manifest.materials[m];
      auto maps = load_material(spec, ctx.cache);
      if (!maps) return maps.error();
      options.materials.push_back({gltf_name, std::move(*maps), spec.options.mapping});
    }
    const fs::path& output = job.outputs.scene;
    if (Status st = ensure_folder(output.parent_path()); !st) return st.error();
    auto exported = exporter::export_scene(s.input, output, options);
    if (!exported) return Error{s.origins.of("input"), "scenes." + s.name + ": " + exported.error().to_string()};
    report.details = to_json(*exported);
    return std::vector<fs::path>(exported->written.begin(), exported->written.end());
  });
}

void run_job(const Job& job, const JobContext& ctx, const fs::path& state_folder, JobReport& report) {
  const auto start = std::chrono::steady_clock::now();
  remove_stamp(job, state_folder);  // from here until it succeeds, the job is not up to date
  std::vector<fs::path> written = job.outputs.all();
  Status status = success();
  if (job.problem) {
    status = *job.problem;
  } else if (job.kind == JobKind::material) {
    status = run_material(job, ctx, report);
  } else if (auto files = run_scene(job, ctx, report); files) {
    written = *files;
  } else {
    status = files.error();
  }
  if (status) status = write_stamp(job, job.inputs, written, state_folder);
  report.outcome = status ? Outcome::built : Outcome::failed;
  if (!status) report.error = status.error();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Result<Report> run(const Manifest& manifest, const Plan& plan, const RunOptions& options) {
  for (const std::string& name : options.only) {
    if (std::none_of(plan.jobs.begin(), plan.jobs.end(), [&](const Job& j) { return j.name == name; })) {
      std::string names;
      for (const Job& j : plan.jobs) names += (names.empty() ? "" : ", ") + j.name;
      return Error{manifest.file.string(), "no job '" + name + "' (jobs: " + names + ")", true};
    }
  }
  Report report;
  std::vector<std::size_t> to_run;
  for (const Job& job : plan.jobs) {
    if (!options.only.empty() && std::find(options.only.begin(), options.only.end(), job.name) == options.only.end()) continue;
    JobReport r;
    r.job = &job;
    r.reason = options.force ? "forced" : out_of_date_reason(job, plan.state_folder, !options.dry_run);
    if (job.problem && options.dry_run) {  // it would fail: said now, not after a "would build"
      r.outcome = Outcome::failed;
      r.error = job.problem;
    } else if (job.problem || !r.reason.empty()) {
      r.outcome = Outcome::out_of_date;
      to_run.push_back(report.jobs.size());
    }
    report.jobs.push_back(std::move(r));
  }
  if (options.dry_run) return report;
  if (Status s = ensure_folder(plan.state_folder); !s) return s.error();

  std::map<fs::path, std::size_t> uses;
  for (std::size_t i : to_run) {
    for (const fs::path& f : decoded_files(*report.jobs[i].job, manifest)) ++uses[f];
  }
  DecodeCache cache(uses);
  auto table = manifest.table.empty() ? Result<std::vector<material_table::Material>>(material_table::builtin_table())
                                      : material_table::load_table(manifest.table);
  const JobContext ctx{manifest, cache, table ? &*table : nullptr, table ? nullptr : &table.error()};

  std::mutex progress_mutex;
  std::size_t done = 0;
  tbb::parallel_for_each(to_run.begin(), to_run.end(), [&](std::size_t i) {
    JobReport& r = report.jobs[i];
    // Isolated: a worker waiting inside this job's own parallel loops does not start another job,
    // which would hold a second job's images at once.
    tbb::this_task_arena::isolate([&] { run_job(*r.job, ctx, plan.state_folder, r); });
    for (const fs::path& f : decoded_files(*r.job, manifest)) cache.release(f);
    std::lock_guard lock(progress_mutex);
    ++done;
    if (options.progress) options.progress(r, done, to_run.size());
  });
  report.images_decoded = cache.decoded();
  return report;
}

}  // namespace matbake::pipeline
