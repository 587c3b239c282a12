// Running a plan: the out-of-date jobs in parallel, each source file decoded once and freed when
// the last job that reads it is done.
#include <tbb/parallel_for.h>
#include <tbb/parallel_for_each.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <set>

#include "matbake/build_progress.hpp"
#include "matbake/join.hpp"
#include "matbake/near_names.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/read_file.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/preview.hpp"
#include "matbake/material_table.hpp"
#include "matbake/report_json.hpp"
#include "matbake/validate.hpp"
#include "matbake/workflow_maps.hpp"
#include "../delivery/encode_cache.hpp"
#include "made_log.hpp"
#include "scene_bake.hpp"
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

  // The file's bytes are read once per transfer, identified (size, time, hash) as they are read and
  // decoded from memory, so a job's stamp records what it decoded, not what the file holds later.
  Result<std::shared_ptr<const image::Image>> read(const fs::path& file, color::Transfer transfer) {
    Entry* entry = nullptr;
    {
      std::lock_guard lock(mutex_);
      auto& e = entries_[key(file)];
      if (!e) e = std::make_unique<Entry>(0);  // not declared: decoded, kept until the run ends
      entry = e.get();
    }
    std::lock_guard lock(entry->mutex);  // a second reader of the same file waits for the first decode
    if (const auto found = entry->images.find(transfer); found != entry->images.end()) return found->second;
    if (Status s = image::check_image_file(file); !s) return s.error();
    const std::optional<std::int64_t> mtime = modification_time(file);
    std::vector<unsigned char> bytes;
    if (!mtime || !read_whole_file(file, bytes)) return Error{file.string(), "cannot be read"};
    auto decoded = image::decode_image(bytes, file, transfer);
    if (!decoded) return decoded.error();
    const FileIdentity read{bytes.size(), *mtime, content_hash(bytes)};
    if (!entry->read) entry->read = read;
    if (entry->read->hash != read.hash) entry->read->hash = "read twice, differently";  // matches no file
    ++decoded_;
    auto shared = std::make_shared<const image::Image>(std::move(*decoded));
    entry->images[transfer] = shared;
    return shared;
  }

  // What the run decoded of `file`, when it did.
  std::optional<FileIdentity> identity(const fs::path& file) {
    std::lock_guard lock(mutex_);
    const auto found = entries_.find(key(file));
    if (found == entries_.end()) return std::nullopt;
    std::lock_guard entry_lock(found->second->mutex);
    return found->second->read;
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
  static fs::path key(const fs::path& file) { return fs::absolute(file).lexically_normal(); }

  struct Entry {
    explicit Entry(std::size_t n) : uses(n) {}
    std::mutex mutex;
    std::map<color::Transfer, std::shared_ptr<const image::Image>> images;
    std::optional<FileIdentity> read;  // the bytes first decoded (kept when the images are freed)
    std::size_t uses;
  };
  std::mutex mutex_;
  std::map<fs::path, std::unique_ptr<Entry>> entries_;
  std::atomic<std::size_t> decoded_{0};
};

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
  const Plan& plan;
  DecodeCache& cache;
  const std::vector<material_table::Material>* table;  // null when it could not be read
  const Error* table_error;
  std::uint64_t encode_cache_bytes;  // OUT/.matbake/encode-cache's limit
};

Status ensure_folder(const fs::path& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) return Error{folder.string(), "cannot make the output folder: " + ec.message()};
  return success();
}

// The flag most texels have, in the words of the material's own workflow: "; most: ... (N texels)".
std::string most_flagged(const validate::Report& report) {
  const auto most = std::max_element(report.flag_counts.begin(), report.flag_counts.end());
  if (*most == 0) return "";
  const int bit = int(most - report.flag_counts.begin());
  return "; most: " + std::string(validate::flag_meaning(bit, report.vocabulary)) + " (" + std::to_string(*most) + " texels)";
}

// Validation of the material as authored; a job error when more texels are flagged than allowed
// and the check is a gate, else a warning (the report's `validation.passed` says so).
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
                                  {"passed", passed},
                                  {"gate", options.gate}};
  const fs::path& json_file = outputs.validation_report;
  report.details["validation"]["report"] = json_file.string();
  if (Status s = write_validation_report(*result, options, json_file); !s) return s;
  if (m.validation.heatmap) {
    if (Status s = validate::write_heatmap(*result, outputs.heatmap); !s) return s;
  }
  char line[200];
  std::snprintf(line, sizeof line, "validation: %zu of %zu texels flagged (%.3g%%; max_violations %.3g%%)%s",
                result->violations, result->checked, 100 * result->violation_fraction(), 100 * options.max_violations,
                passed || options.gate ? "" : ", over the limit (advisory: validate.gate is off)");
  // The failure is the material's (or its max_violations', when it sets one); the report says which texels.
  if (!passed && options.gate) {
    return Error{m.origins.of("validate.max_violations"),
                 "materials." + m.name + ": " + line + "; the texels are in " + json_file.string()};
  }
  if (result->violations) report.warnings.push_back(line + most_flagged(*result));
  return success();
}

// The material's textures in its layout's workflow (converted when the layout needs the other one).
Status write_layout(const Job& job, const JobContext& ctx, const MaterialSpec& m, material::Maps maps, JobReport& report) {
  const pack::Layout& layout = m.layout->layout;
  const bool converts = workflow::layout_direction(maps, layout).has_value();
  auto in_workflow = workflow::in_layout_workflow(std::move(maps), layout, m.options.mapping);
  if (!in_workflow) {
    return Error{m.origins.of("layout"), "materials." + m.name + ".layout: " + in_workflow.error().to_string()};
  }
  if (converts) report.details["conversion"] = to_json(*in_workflow, m.options.mapping);
  const std::vector<std::string> outputs{material_texture_pattern(ctx.manifest, m).string()};
  auto written = pack::write_textures(layout, in_workflow->maps,
                                      {outputs, m.options.bits, m.options.transfer, decoded_files(m), {}, m.encoding});
  if (!written) return written.error();
  // The plan chose the textures from the maps' names, the writer from the maps: one rule, so a
  // difference is a bug (a written file the build does not know, or a planned one never written).
  if (*written != job.outputs.textures) return Error{m.name, "internal error: the textures written are not the planned ones"};
  return success();
}

// The material's ball as the preview command renders it (one cell, its maps over the ball, the
// default light rig and model) as an sRGB PNG: what the report page shows for it.
Status write_preview(const MaterialSpec& m, const material::Maps& maps, const fs::path& path) {
  auto material = preview::material_from_maps(m.name, maps);
  if (!material) return material.error();
  auto rendered = preview::render({*material}, preview::Options{});
  if (!rendered) return rendered.error();
  const image::WriteOptions png{color::Transfer::srgb, image::SampleType::u8, "", "sRGB", m.encoding.png_level};
  return image::write_image(rendered->image, path, png);
}

// Validated first: a gate that fails writes no textures (a failed job's outputs are not fresh ones).
Status run_material(const Job& job, const JobContext& ctx, const StageReport& stage, JobReport& report) {
  return guarded(ctx.manifest.materials[job.spec].name, [&]() -> Status {
    const MaterialSpec& m = ctx.manifest.materials[job.spec];
    report_stage(stage, Phase::read, "decoding sources");
    auto maps = load_material(m, ctx.cache);
    if (!maps) return maps.error();
    for (std::string& note : pack::decode_overrides(m.sources, m.options)) report.warnings.push_back(std::move(note));
    report.details["size"] = {maps->width, maps->height};
    if (Status s = ensure_folder(ctx.manifest.output / "materials"); !s) return s;
    if (m.validation.enabled) {
      report_stage(stage, Phase::textures, "validating");
      if (Status s = validate_material(m, *maps, ctx, job.outputs, report); !s) return s;
    }
    report_stage(stage, Phase::textures, "writing textures", m.validation.enabled ? 0.5 : 0);
    if (Status s = write_preview(m, *maps, job.outputs.preview); !s) return s;
    if (m.layout) return write_layout(job, ctx, m, std::move(*maps), report);
    return success();
  });
}

// The export's options of a scene job: the scene's, with the maps of the manifest's materials it uses.
Result<exporter::Options> scene_options(const Job& job, const Manifest& manifest, DecodeCache& cache) {
  exporter::Options options = manifest.scenes[job.spec].options;
  for (const auto& [gltf_name, m] : job.materials) {
    const MaterialSpec& spec = manifest.materials[m];
    auto maps = load_material(spec, cache);
    if (!maps) return maps.error();
    options.materials.push_back({gltf_name, std::move(*maps), spec.options.mapping});
  }
  return options;
}

Result<std::vector<fs::path>> run_scene(const Job& job, const JobContext& ctx, const fs::path& state_folder,
                                        const StageReport& stage, JobReport& report) {
  return guarded(ctx.manifest.scenes[job.spec].input.string(), [&]() -> Result<std::vector<fs::path>> {
    const SceneSpec& s = ctx.manifest.scenes[job.spec];
    report_stage(stage, Phase::read, "decoding materials");
    auto found = scene_options(job, ctx.manifest, ctx.cache);
    if (!found) return found.error();
    exporter::Options& options = *found;
    options.stage = stage;
    // Content-keyed, so shared by every manifest that builds into the folder.
    options.delivery.encode_cache = ctx.manifest.output / ".matbake" / "encode-cache";
    options.delivery.encode_cache_bytes = ctx.encode_cache_bytes;
    const fs::path& output = job.outputs.scene;
    if (Status st = ensure_folder(output.parent_path()); !st) return st.error();
    std::optional<BakedScene> baked;
    std::vector<fs::path> map_targets;
    std::optional<OutputGate> gate;  // what the bake moves and removes passes it
    if (s.bake) {
      gate.emplace(output_gate(ctx.manifest, ctx.plan));
      report_stage(stage, Phase::ao, "baking from " + s.bake->from);
      auto made = bake_scene(job, s, state_folder, options.encoding);
      if (!made) return made.error();
      if (Status st = check_baked_materials(s, *made, options.materials); !st) return st.error();
      for (const std::string& w : made->report.warnings) report.warnings.push_back("scenes." + s.name + ".bake: " + w);
      for (const bake::TextureReport& t : made->report.textures) {  // a placement's copy takes its original's
        for (exporter::MaterialMaps& g : options.materials) {
          if (!t.copy_of.empty() && g.material == t.copy_of) g.copies.push_back(t.name);
        }
      }
      auto targets = baked_map_targets(job, *made, *gate);
      if (!targets) return targets.error();
      map_targets = std::move(*targets);
      baked = std::move(*made);
    }
    auto exported = exporter::export_scene(baked ? baked->gltf : s.input, output, options);
    if (!exported) return Error{s.origins.of("input"), "scenes." + s.name + ": " + exported.error().to_string()};
    report.details = to_json(*exported);
    std::vector<fs::path> written(exported->written.begin(), exported->written.end());
    if (baked) {
      auto maps = finish_bake(*baked, std::move(map_targets), *gate);
      if (!maps) return maps.error();
      written.insert(written.end(), maps->begin(), maps->end());
      report.details["bake"] = to_json(baked->report);
      report.details["bake"].erase("written");  // the bake's own files, removed or moved (in `written`)
    }
    return written;
  });
}

// The inputs the decode cache does not read (layout files, the table, a scene's glTF, buffers and
// images), identified before the job reads them: a change while it runs then shows as a difference
// next time (a rebuild), never as an output from other bytes stamped fresh.
std::vector<StampedFile> identify_other_inputs(const Job& job, const std::vector<fs::path>& decoded) {
  std::vector<StampedFile> read;
  for (const fs::path& in : job.inputs) {
    if (std::binary_search(decoded.begin(), decoded.end(), in)) continue;
    if (auto identity = identify(in)) read.push_back({in, *identity});  // else the job fails reading it
  }
  return read;
}

// Every input as the job read it; those that changed since are listed in `moved`.
std::vector<StampedFile> inputs_as_read(std::vector<StampedFile> read, const std::vector<fs::path>& decoded,
                                        DecodeCache& cache, std::vector<fs::path>& moved) {
  for (const fs::path& f : decoded) {
    std::optional<FileIdentity> identity = cache.identity(f);
    if (!identity) identity = identify(f);  // declared but not decoded: it did not decide the outputs
    if (identity) read.push_back({f, *identity});
  }
  for (const StampedFile& f : read) {
    if (changed_since(f.path, f.identity)) moved.push_back(f.path);
  }
  return read;
}

void run_job(const Job& job, const JobContext& ctx, const RunOptions& run_options, const StampRoots& roots,
             JobReport& report) {
  const auto start = std::chrono::steady_clock::now();
  StageReport stage;
  if (BuildProgress* tracker = run_options.tracker) {
    tracker->started(job, start);
    stage = [tracker, &job](Phase phase, std::string_view what, double fraction) { tracker->stage(job, phase, what, fraction); };
  }
  remove_stamp(job.name, roots);  // from here until it succeeds, the job is not up to date
  remove_failure(job.name, roots);  // nor failed: running (or, if it is killed, not built)
  const std::vector<fs::path> decoded = decoded_files(job, ctx.manifest);
  std::vector<StampedFile> read = identify_other_inputs(job, decoded);
  std::vector<fs::path> written = job.outputs.all();
  Status status = success();
  if (job.problem) {
    status = *job.problem;
  } else if (job.kind == JobKind::material) {
    status = run_material(job, ctx, stage, report);
  } else if (auto files = run_scene(job, ctx, roots.state_folder, stage, report); files) {
    written = *files;
  } else {
    status = files.error();
  }
  if (status) {
    if (run_options.before_stamp) run_options.before_stamp(job);
    read = inputs_as_read(std::move(read), decoded, ctx.cache, report.moved);
    auto made = identify_all(written);
    const nlohmann::json summary = {
        {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()},
        {"details", report.details},
        {"warnings", report.warnings}};
    status = made ? write_stamp(job, read, *made, summary, roots) : Status(made.error());
    if (made) {
      for (const StampedFile& f : *made) report.written[f.path] = f.identity.hash;
    }
  }
  report.outcome = status ? Outcome::built : Outcome::failed;
  if (!status) {
    report.error = status.error();
    record_failure(job.name, status.error(), roots);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A scene whose last build gave a glTF material a manifest material that the manifest no longer
// has would silently fall back to the glTF's own material: the run stops and says so.
Status check_scene_materials(const Manifest& manifest, const Plan& plan, const StampRoots& roots) {
  for (const Job& job : plan.jobs) {
    if (job.kind != JobKind::scene) continue;
    const StateText read = read_state_file(roots.state_folder / (job_file_stem(job.name) + ".json"), kStampLimit);
    const nlohmann::json& stamp = read.json;
    if (!read.problem.empty() || !stamp.is_object() || !stamp.contains("options") || !stamp["options"].is_string()) continue;
    const nlohmann::json options = options_json(stamp["options"].get<std::string>());
    if (!options.is_object() || !options.contains("materials") || !options["materials"].is_object()) continue;
    for (const auto& [gltf_name, material] : options["materials"].items()) {
      if (job.materials.count(gltf_name)) continue;
      const SceneSpec& s = manifest.scenes[job.spec];
      return Error{s.origins.of(""), "scenes." + s.name + ": its glTF material '" + gltf_name +
                                         "' was built with a manifest material the manifest no longer gives it; the scene would "
                                         "fall back to the glTF's own material: restore it, or allow it with " + mention("prune", "true")};
    }
  }
  return success();
}

MadeLog read_log(const StampRoots& roots, Report& report) {
  std::string problem;
  MadeLog log = read_made_log(roots, problem);
  if (!problem.empty()) {
    report.warnings.push_back((roots.state_folder / "made.json").string() + " " + problem +
                              "; ignored (a new log is started, no file it lists is removed)");
  }
  return log;
}

// The log of files made, brought up to date, the stamps of jobs the manifest no longer has removed,
// and after a full run with no failure the stale files too (unless kept).
Status finish_run(const Manifest& manifest, const Plan& plan, const RunOptions& options, const StampRoots& roots, Report& report) {
  const MadeLogLock lock(roots);
  if (!lock.problem().empty()) return Error{"", lock.problem()};
  const MadeLog before = read_log(roots, report);
  MadeLog log = before;
  for (const std::string& name : record_run(log, plan, report, roots)) {
    remove_stamp(name, roots);
    remove_failure(name, roots);
  }
  const bool full = options.only.empty() && report.count(Outcome::failed) == 0;
  std::size_t made = log.stale.size();
  for (const auto& [name, files] : log.jobs) made += files.size();
  const bool prune = options.prune || manifest.prune;
  const bool too_many = log.stale.size() > kPruneMinimum && double(log.stale.size()) > kPruneShare * double(made);
  report.stale = clean_stale(log, output_gate(manifest, plan), roots, full && !options.keep_stale && (prune || !too_many));
  if (full && !options.keep_stale) remove_stale_bakes(plan, manifest);
  if (full && !options.keep_stale && !prune && too_many && !report.stale.kept.empty()) {
    report.stale.held_back = "this run would remove " + std::to_string(report.stale.kept.size()) + " of the " + std::to_string(made) +
                             " files the build made (more than half: a renamed folder or a lost input looks like this); "
                             "they are kept: " + mention("prune", "true") + " removes them";
  }
  return log == before ? success() : write_made_log(log, roots);  // a no-op run writes nothing
}

}  // namespace

Result<Report> run(const Manifest& manifest, const Plan& plan, const RunOptions& options) {
  for (const std::string& name : options.only) {
    if (std::none_of(plan.jobs.begin(), plan.jobs.end(), [&](const Job& j) { return j.name == name; })) {
      std::vector<std::string> names;
      for (const Job& j : plan.jobs) names.push_back(j.name);
      const std::string near = did_you_mean(name, names);
      return Error{manifest.file.string(), "no job '" + name + "'" + (near.empty() ? " (jobs: " + join(names, ", ") + ")" : near), true};
    }
  }
  const StampRoots roots{plan.state_folder, manifest.folder, manifest.output};
  Report report;
  if (Status s = claim_output_folder(manifest, plan, !options.dry_run, report.warnings); !s) return s.error();
  if (!options.prune && !manifest.prune) {
    if (Status s = check_scene_materials(manifest, plan, roots); !s) return s.error();
  }
  std::vector<const Job*> selected;
  for (const Job& job : plan.jobs) {
    if (options.only.empty() || std::find(options.only.begin(), options.only.end(), job.name) != options.only.end()) {
      selected.push_back(&job);
    }
  }
  // The stamps read in parallel: a no-op run of a large manifest is mostly this.
  std::vector<std::string> reasons(selected.size(), "forced");
  std::vector<std::map<fs::path, std::string>> recorded(selected.size());
  std::vector<nlohmann::json> changed(selected.size());
  if (!options.force) {
    tbb::parallel_for(std::size_t(0), selected.size(), [&](std::size_t i) {
      reasons[i] = out_of_date_reason(*selected[i], roots, !options.dry_run, &recorded[i], &changed[i]);
    });
  }
  std::vector<std::size_t> to_run;
  for (std::size_t i = 0; i < selected.size(); ++i) {
    const Job& job = *selected[i];
    JobReport r;
    r.job = &job;
    r.reason = std::move(reasons[i]);
    r.changed = std::move(changed[i]);
    r.written = std::move(recorded[i]);  // up to date: its outputs as its stamp records them
    if (job.problem && options.dry_run) {  // it would fail: said now, not after a "would build"
      r.outcome = Outcome::failed;
      r.error = job.problem;
    } else if (job.problem || !r.reason.empty()) {
      r.outcome = Outcome::out_of_date;
      to_run.push_back(report.jobs.size());
    }
    report.jobs.push_back(std::move(r));
  }
  for (const JobReport& r : report.jobs) {
    if (r.reason.rfind(kBadStamp, 0) == 0) report.warnings.push_back(r.reason.substr(std::string_view(kBadStamp).size()) + "; " + r.job->name + " rebuilds");
  }
  if (options.dry_run) {
    MadeLog log = read_log(roots, report);
    record_run(log, plan, report, roots);
    report.stale = clean_stale(log, output_gate(manifest, plan), roots, false);
    return report;
  }
  if (Status s = ensure_folder(plan.state_folder); !s) return s.error();

  std::map<fs::path, std::size_t> uses;
  for (std::size_t i : to_run) {
    for (const fs::path& f : decoded_files(*report.jobs[i].job, manifest)) ++uses[f];
  }
  DecodeCache cache(uses);
  auto table = manifest.table.empty() ? Result<std::vector<material_table::Material>>(material_table::builtin_table())
                                      : material_table::load_table(manifest.table);
  auto encode_cache_bytes = delivery::encode_cache_limit();
  if (!encode_cache_bytes) return encode_cache_bytes.error();
  const JobContext ctx{manifest, plan, cache, table ? &*table : nullptr, table ? nullptr : &table.error(), *encode_cache_bytes};

  // Jobs that depend on none first, then the others (a scene after its materials' jobs), each
  // skipped when a job it depends on failed in this run.
  std::map<std::string, const JobReport*> by_name;
  for (const JobReport& r : report.jobs) by_name[r.job->name] = &r;
  const auto failed_dependency = [&](const Job& job) -> std::string {
    for (const std::string& name : job.depends_on) {
      const auto found = by_name.find(name);
      if (found != by_name.end() && (found->second->outcome == Outcome::failed || found->second->outcome == Outcome::skipped)) {
        return name;
      }
    }
    return {};
  };
  if (options.tracker) {
    std::vector<std::pair<const Job*, JobWork>> work(to_run.size());
    tbb::parallel_for(std::size_t(0), to_run.size(), [&](std::size_t i) {
      const Job& job = *report.jobs[to_run[i]].job;
      work[i] = {&job, job_work(job, manifest)};
    });
    options.tracker->planned(work, std::chrono::steady_clock::now());
  }
  std::vector<std::size_t> waves[2];
  for (std::size_t i : to_run) waves[report.jobs[i].job->depends_on.empty() ? 0 : 1].push_back(i);
  std::mutex progress_mutex;
  std::size_t done = 0;
  for (const std::vector<std::size_t>& wave : waves) {
    tbb::parallel_for_each(wave.begin(), wave.end(), [&](std::size_t i) {
      JobReport& r = report.jobs[i];
      if (const std::string failed = failed_dependency(*r.job); !failed.empty()) {
        r.outcome = Outcome::skipped;
        r.reason = failed + " failed";
      } else {
        // Isolated: a worker waiting inside this job's own parallel loops does not start another job,
        // which would hold a second job's images at once.
        tbb::this_task_arena::isolate([&] { run_job(*r.job, ctx, options, roots, r); });
      }
      for (const fs::path& f : decoded_files(*r.job, manifest)) cache.release(f);
      if (options.tracker) options.tracker->finished(*r.job);
      std::lock_guard lock(progress_mutex);
      ++done;
      if (options.progress) options.progress(r, done, to_run.size());
    });
  }
  report.images_decoded = cache.decoded();
  // The log is a convenience (stale files found later), not an output: a full disk or a read-only
  // folder that lets no job write has already failed the jobs, each with its error line.
  if (Status s = finish_run(manifest, plan, options, roots, report); !s) {
    report.warnings.push_back("the log of files made was not updated: " + s.error().to_string());
  }
  return report;
}

Result<std::vector<delivery::TextureReport>> plan_scene(const Manifest& manifest, const Job& job) {
  const SceneSpec& s = manifest.scenes[job.spec];
  return guarded(s.input.string(), [&]() -> Result<std::vector<delivery::TextureReport>> {
    DecodeCache cache({});
    auto options = scene_options(job, manifest, cache);
    if (!options) return options.error();
    options->plan_only = true;
    auto planned = exporter::export_scene(s.input, job.outputs.scene, *options);
    if (!planned) return Error{s.origins.of("input"), "scenes." + s.name + ": " + planned.error().to_string()};
    return std::move(planned->textures);
  });
}

}  // namespace matbake::pipeline
