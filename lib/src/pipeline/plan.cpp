// The jobs of a manifest, what each reads and writes, and the files build systems read: Make
// depfiles and a Ninja file.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <set>
#include <unordered_map>

#include "../gltf/document.hpp"
#include "scene_bake.hpp"
#include "state.hpp"
#include "matbake/join.hpp"
#include "matbake/delivery.hpp"
#include "matbake/encoding_params.hpp"
#include "matbake/material_params.hpp"
#include "matbake/pipeline_params.hpp"
#include "matbake/validate_params.hpp"
#include "matbake/material_table.hpp"
#include "matbake/near_names.hpp"
#include "matbake/output_check.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/report_json.hpp"
#include "matbake/script_text.hpp"
#include "matbake/version.hpp"
#include "matbake/workflow_maps.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

fs::path normalized(const fs::path& p) {
  std::error_code ec;
  return fs::absolute(p, ec).lexically_normal();
}

// A file the manifest names as its stamp's options hold it: relative to the manifest's folder, so
// that the same manifest in a moved or copied tree has the same options.
std::string manifest_relative(const fs::path& file, const Manifest& manifest) {
  const fs::path relative = normalized(file).lexically_relative(manifest.folder);
  return relative.empty() ? normalized(file).generic_string() : relative.generic_string();
}

// What a scene job reads of a material, for its stamp: the maps as loaded (sources, packed
// textures, the parameters that decode and size them) and the gloss mapping; not how the
// material's own job writes or validates them, so changing that rebuilds the material only.
nlohmann::json material_reads(const MaterialSpec& m, const Manifest& manifest) {
  nlohmann::json options = nlohmann::json::object();
  for (const params::Param<pack::MaterialOptions>& p : pack::material_params().params) {
    if (!p.spec.written_only) options[p.spec.name] = p.get(m.options);
  }
  nlohmann::json sources = nlohmann::json::object();
  for (const pack::SourceInput& s : m.sources) {
    const std::string channels = s.channels == pack::FileChannels::as_stored ? "" : ":" + std::string(name_in(pack::kFileChannelNames, s.channels));
    sources[s.name] = s.file.empty() ? nlohmann::json(s.constant) : nlohmann::json(manifest_relative(s.file, manifest) + channels);
  }
  std::vector<std::string> packed;
  for (const fs::path& f : m.packed_files) packed.push_back(manifest_relative(f, manifest));
  options.update(nlohmann::json{{"sources", sources},
                                {"packed", {{"layout", m.packed ? m.packed->reference : ""}, {"files", packed}}}});
  return options;
}

// What a material's own job reads, for its stamp: the maps as a scene reads them, and what writes
// its layout's textures (when it has a layout) and validates them (when validation is on).
nlohmann::json material_options(const MaterialSpec& m, const Manifest& manifest) {
  nlohmann::json options = material_reads(m, manifest);
  if (m.layout) {
    options.update(params::to_json(image::encoding_params(), m.encoding));
    options.update(params::to_json(pack::material_params(), m.options));
    options["layout"] = m.layout->reference;
  }
  options["validate"] = params::to_json(validation_params(), m.validation);
  if (m.validation.enabled) {
    options["validate"].update(params::to_json(validate::options_params(), m.validation.options));
    options["reference"] = m.reference;
    options["table"] = manifest.table.empty() ? "" : manifest_relative(manifest.table, manifest);
  } else {
    options["validate"].erase("heatmap");
  }
  return options;
}

std::vector<fs::path> material_inputs(const MaterialSpec& m, const Manifest& manifest) {
  std::vector<fs::path> inputs;
  for (const pack::SourceInput& s : m.sources) {
    if (!s.file.empty()) inputs.push_back(normalized(s.file));
  }
  for (const fs::path& f : m.packed_files) inputs.push_back(normalized(f));
  // Layout files (not presets) and the material table are read too.
  for (const std::optional<LayoutChoice>& layout : {m.layout, m.packed}) {
    if (layout && !layout->file.empty()) inputs.push_back(normalized(layout->file));
  }
  if (!manifest.table.empty() && m.validation.enabled) inputs.push_back(normalized(manifest.table));
  return inputs;
}

// What makes a material's jobs fail before they start: a source file that is not there, or a
// reference the material table does not have. Errors name the manifest's line and column.
std::optional<std::string> file_problem(const fs::path& file) {
  std::error_code ec;
  if (fs::is_regular_file(file, ec)) return std::nullopt;
  return Error{file.string(), fs::exists(file, ec) ? "is not a regular file" : "no such file"}.to_string();
}

std::optional<Error> material_problem(const MaterialSpec& m, const Result<std::vector<material_table::Material>>& table,
                                      const Origins& manifest_origins) {
  for (const pack::SourceInput& s : m.sources) {
    if (auto problem = s.file.empty() ? std::nullopt : file_problem(s.file)) {
      return Error{m.origins.of("sources." + s.name), "materials." + m.name + ".sources." + s.name + ": " + *problem};
    }
  }
  for (const fs::path& f : m.packed_files) {
    if (auto problem = file_problem(f)) {
      return Error{m.origins.of("packed.files"), "materials." + m.name + ".packed.files: " + *problem};
    }
  }
  if (m.reference.empty() || !m.validation.enabled) return std::nullopt;
  if (!table) return Error{manifest_origins.of("table"), "table: " + table.error().to_string()};
  if (auto found = material_table::lookup(*table, m.reference); !found) {
    return Error{m.origins.of("reference"), "materials." + m.name + ".reference: " + found.error().message};
  }
  return std::nullopt;
}

void add_unique(std::vector<fs::path>& to, const std::vector<fs::path>& from) {
  for (const fs::path& p : from) {
    if (std::find(to.begin(), to.end(), p) == to.end()) to.push_back(p);
  }
}

// A material's job: what it reads and writes, its options, and what makes it fail before it starts.
Result<Job> material_job(const Manifest& manifest, std::size_t i, const Result<std::vector<material_table::Material>>& table) {
  const MaterialSpec& m = manifest.materials[i];
  const fs::path materials_folder = manifest.output / "materials";
  Job job;
  job.kind = JobKind::material;
  job.spec = i;
  job.name = "material:" + m.name;
  job.inputs = material_inputs(m, manifest);
  job.options = material_options(m, manifest).dump();
  job.problem = material_problem(m, table, manifest.origins);
  if (m.layout) {
    auto paths = pack::output_paths(m.layout->layout, {material_texture_pattern(manifest, m).string()});
    if (!paths) return Error{m.origins.of("layout"), "materials." + m.name + ".layout: " + paths.error().to_string()};
    // The maps it is written from, in the layout's workflow: what decides which textures it writes.
    const material::MapNames given = workflow::names_in_layout_workflow(source_map_names(m), m.layout->layout);
    for (std::size_t t = 0; t < paths->size(); ++t) {
      if (pack::texture_written(m.layout->layout.textures[t], given)) job.outputs.textures.push_back((*paths)[t]);
    }
  }
  if (m.validation.enabled) {
    job.outputs.validation_report = materials_folder / (m.name + ".validation.json");
    if (m.validation.heatmap) job.outputs.heatmap = materials_folder / (m.name + "_validation.png");
  }
  // Its ball beside what it writes; a material only scenes use has no job, and no ball.
  if (!job.outputs.all().empty()) job.outputs.preview = materials_folder / (m.name + "_preview.png");
  return job;
}

}  // namespace

material::MapNames source_map_names(const MaterialSpec& m) {
  material::MapNames names;
  for (const pack::SourceInput& s : m.sources) names.insert(s.name);
  if (m.packed) {
    for (std::string& n : pack::layout_sources(m.packed->layout)) names.insert(std::move(n));
  }
  return names;
}

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

fs::path material_texture_pattern(const Manifest& manifest, const MaterialSpec& m) {
  return manifest.output / "materials" / (m.name + "_{texture}." + m.options.format);
}

std::vector<fs::path> JobOutputs::all() const {
  std::vector<fs::path> files = textures;
  for (const fs::path* f : {&validation_report, &heatmap, &preview, &scene, &buffer}) {
    if (!f->empty()) files.push_back(*f);
  }
  return files;
}

std::size_t Report::count(Outcome o) const {
  return std::size_t(std::count_if(jobs.begin(), jobs.end(), [&](const JobReport& j) { return j.outcome == o; }));
}

std::size_t Report::moved() const {
  return std::size_t(std::count_if(jobs.begin(), jobs.end(), [](const JobReport& j) { return !j.moved.empty(); }));
}

std::size_t Report::over_validation_limit() const {
  return std::size_t(std::count_if(jobs.begin(), jobs.end(), [](const JobReport& j) {
    return j.details.contains("validation") && !j.details["validation"].value("passed", true);
  }));
}

// A baking scene reads its high-poly's files too, and its cage mesh's.
void add_high_poly(Job& job, const SceneSpec& s) {
  for (const auto& [file, key] : {std::pair{s.bake->high, "from"}, std::pair{s.bake->cage, "cage"}}) {
    if (file.empty()) continue;
    auto json = gltf::read_json(file);
    if (!json) {
      if (!job.problem) {
        job.problem = Error{s.origins.of(std::string("bake.") + key), "scenes." + s.name + ".bake." + key + ": " + json.error().to_string()};
      }
      add_unique(job.inputs, {normalized(file)});
      continue;
    }
    add_unique(job.inputs, gltf::source_files(file, *json));
  }
}

Result<Plan> make_plan(const Manifest& manifest) {
  return guarded(manifest.file.string(), [&]() -> Result<Plan> {
    Plan plan;
    plan.warnings = manifest.notes;
    // The manifest as its output folder knows it: its path from there (a moved or copied tree keeps it).
    plan.owner = stamped_path(manifest.file, manifest.output);
    plan.state_folder = manifest.output / ".matbake";
    if (manifest.shared_output) {
      const std::string id = content_hash({reinterpret_cast<const unsigned char*>(plan.owner.data()), plan.owner.size()});
      plan.state_folder = plan.state_folder / "shared" / (manifest.file.stem().string() + "-" + id);
    }
    std::vector<bool> used(manifest.materials.size(), false);
    const auto material_index = [&](const std::string& name) -> std::optional<std::size_t> {
      for (std::size_t i = 0; i < manifest.materials.size(); ++i) {
        if (manifest.materials[i].name == name) return i;
      }
      return std::nullopt;
    };

    const bool references = std::any_of(manifest.materials.begin(), manifest.materials.end(),
                                        [](const MaterialSpec& m) { return !m.reference.empty(); });
    const auto table = references ? material_table::table_or_builtin(manifest.table)
                                  : Result<std::vector<material_table::Material>>(std::vector<material_table::Material>{});
    // Each material's job made in parallel (its problems and options are most of a large plan).
    std::vector<Result<Job>> material_jobs(manifest.materials.size(), Job{});
    tbb::parallel_for(std::size_t(0), material_jobs.size(), [&](std::size_t i) {
      material_jobs[i] = material_job(manifest, i, table);
    });

    std::vector<Job> scenes;
    for (std::size_t i = 0; i < manifest.scenes.size(); ++i) {
      const SceneSpec& s = manifest.scenes[i];
      Job job;
      job.kind = JobKind::scene;
      job.spec = i;
      job.name = "scene:" + s.name;
      const fs::path out = manifest.output / s.output;
      job.outputs.scene = out;
      if (out.extension() == ".gltf") job.outputs.buffer = out.parent_path() / (out.stem().string() + ".bin");
      // Which manifest materials the scene gets: named in the spec, or by the glTF material's name.
      std::map<std::string, std::string> assigned = s.materials;
      auto json = gltf::read_json(s.input);
      if (!json) {
        job.problem = Error{s.origins.of("input"), "scenes." + s.name + ".input: " + json.error().to_string()};
        job.inputs.push_back(normalized(s.input));
      } else {
        job.inputs = gltf::source_files(s.input, *json);
        std::set<std::string> names;
        if (json->contains("materials") && (*json)["materials"].is_array()) {
          for (const auto& m : (*json)["materials"]) {
            if (m.is_object() && m.contains("name") && m["name"].is_string()) names.insert(m["name"].get<std::string>());
          }
        }
        for (const auto& [gltf_name, material] : s.materials) {
          if (!names.count(gltf_name)) {
            job.problem = Error{s.origins.of("materials." + gltf_name),
                                "scenes." + s.name + ".materials names '" + gltf_name + "', but " + s.input.string() +
                                    " has no material of that name" +
                                    did_you_mean(gltf_name, std::vector<std::string>(names.begin(), names.end()))};
          }
        }
        if (s.match_names) {
          for (const std::string& n : names) {
            if (!assigned.count(n) && material_index(n)) assigned[n] = n;
          }
        }
      }
      nlohmann::json materials = nlohmann::json::object();
      for (const auto& [gltf_name, material] : assigned) {
        const std::size_t m = *material_index(material);
        used[m] = true;
        job.materials[gltf_name] = m;
        add_unique(job.inputs, material_inputs(manifest.materials[m], manifest));
        if (!job.problem && material_jobs[m]) job.problem = material_jobs[m]->problem;
        materials[gltf_name] = material_reads(manifest.materials[m], manifest);
      }
      nlohmann::json options = {{"input", manifest_relative(s.input, manifest)},
                                {"output", s.output.string()},
                                {"materials", materials},
                                {"export", to_json(s.options)}};
      if (s.bake) {
        options["bake"] = params::tree_json(scene_tree(), s)["bake"];
        add_high_poly(job, s);
      }
      // The encoder's version too: a new basisu rebuilds the KTX2 scenes.
      if (s.options.delivery.texture_format == delivery::TextureFormat::ktx2) options["encoder"] = delivery::encoder_identity();
      job.options = options.dump();
      scenes.push_back(std::move(job));
    }

    for (std::size_t i = 0; i < manifest.materials.size(); ++i) {
      const MaterialSpec& m = manifest.materials[i];
      if (!material_jobs[i]) return material_jobs[i].error();
      Job& job = *material_jobs[i];
      if (!m.layout && !used[i] && !m.validation.enabled) {
        plan.warnings.push_back("materials." + m.name +
                                ": no layout, no validation and no scene uses it, so nothing is built from it");
        continue;
      }
      if (job.outputs.all().empty()) continue;  // used by scenes only, nothing of its own to write
      plan.jobs.push_back(std::move(job));
    }
    std::set<std::string> made_jobs;
    for (const Job& j : plan.jobs) made_jobs.insert(j.name);
    for (Job& s : scenes) {
      std::set<std::string> needed;
      for (const auto& [gltf_name, m] : s.materials) {
        const std::string material_job = "material:" + manifest.materials[m].name;
        if (made_jobs.count(material_job)) needed.insert(material_job);
      }
      s.depends_on.assign(needed.begin(), needed.end());
      plan.jobs.push_back(std::move(s));
    }

    // No file written twice, no input written at all (by the output gate: real path and identity),
    // and nothing written outside the output folder's real path (a link inside it to elsewhere).
    std::vector<fs::path> inputs{manifest.file};
    for (const Job& job : plan.jobs) inputs.insert(inputs.end(), job.inputs.begin(), job.inputs.end());
    const OutputGate gate(manifest.output, inputs);
    std::vector<fs::path> state_folders{plan.state_folder};
    for (const Job& job : plan.jobs) {
      if (job.kind == JobKind::scene && manifest.scenes[job.spec].bake) {
        for (fs::path& folder : bake_folders(plan.state_folder, job)) state_folders.push_back(std::move(folder));
      }
    }
    for (const fs::path& folder : state_folders) {
      if (!gate.holds(folder)) return Error{folder.string(), "is a link out of the output folder; matbake writes only inside it"};
    }
    std::unordered_map<std::string, std::string> writers;
    for (const Job& job : plan.jobs) {
      for (const fs::path& out : job.outputs.all()) {
        if (!gate.holds(out)) {
          return Error{out.string(), job.name + " would be written outside the output folder (through a link); matbake writes only inside it"};
        }
        if (gate.is_protected(out)) return Error{out.string(), job.name + " would overwrite an input; matbake never does"};
        if (const auto [it, added] = writers.emplace(out.native(), job.name); !added) {
          return Error{out.string(), "written by both " + it->second + " and " + job.name};
        }
      }
    }
    return plan;
  });
}

OutputGate output_gate(const Manifest& manifest, const Plan& plan) {
  std::vector<fs::path> protect{manifest.file};
  for (const Job& job : plan.jobs) {
    protect.insert(protect.end(), job.inputs.begin(), job.inputs.end());
    for (fs::path& out : job.outputs.all()) protect.push_back(std::move(out));
  }
  return OutputGate(manifest.output, protect);
}

Status check_side_outputs(const Manifest& manifest, const Plan& plan, std::span<const NamedOutput> outputs) {
  const OutputGate gate = output_gate(manifest, plan);
  for (const NamedOutput& out : outputs) {
    if (out.path.empty()) continue;
    if (Status s = gate.check_side_output(out.path, out.role); !s) return s;
  }
  return check_outputs(outputs, {});  // no two are one file
}

Result<std::string> depfile_text(const std::vector<fs::path>& targets, const std::vector<fs::path>& inputs) {
  std::vector<std::string> words;
  for (const fs::path& t : targets) {
    auto path = depfile_path(t.native());
    if (!path) return path.error();
    words.push_back(*path);
  }
  std::string text = join(words, " ") + ":";
  for (const fs::path& in : inputs) {
    auto path = depfile_path(in.native());
    if (!path) return path.error();
    text += " \\\n  " + *path;
  }
  return text + "\n";
}

Status check_depfile_paths(const Manifest& manifest, const Plan& plan) {
  std::vector<fs::path> files{manifest.file};
  for (const Job& job : plan.jobs) {
    files.insert(files.end(), job.inputs.begin(), job.inputs.end());
    for (fs::path& out : job.outputs.all()) files.push_back(std::move(out));
  }
  auto text = depfile_text({}, files);
  if (!text) return text.error();
  return success();
}

namespace {

// A list of paths for a build statement, each after a space.
Result<std::string> ninja_paths(const std::vector<fs::path>& paths) {
  std::string text;
  for (const fs::path& p : paths) {
    auto escaped = ninja_path(p.native());
    if (!escaped) return escaped.error();
    text += " " + *escaped;
  }
  return text;
}

// "name = value" for a word the edge's command passes to the shell.
Result<std::string> shell_variable(const std::string& name, const std::string& word) {
  if (std::string problem = unscriptable(word); !problem.empty()) return Error{word, problem + "; a Ninja file cannot hold it", true};
  return "  " + name + " = " + ninja_value(shell_word(word)) + "\n";
}

Result<std::string> job_edge(const Job& job, const Plan& plan, const std::map<std::string, const Job*>& by_name,
                             const std::string& manifest_path) {
  auto outputs = ninja_paths(job.outputs.all());
  if (!outputs) return outputs.error();
  // Implicit inputs: what it reads, and the outputs of the jobs it depends on (so a failed
  // material stops the scenes that use it, as a build does).
  std::vector<fs::path> implicit = job.inputs;
  for (const std::string& name : job.depends_on) add_unique(implicit, by_name.at(name)->outputs.all());
  auto inputs = ninja_paths(implicit);
  if (!inputs) return inputs.error();
  const fs::path depfile = plan.state_folder / (job_file_stem(job.name) + ".d");
  auto depfile_ninja = ninja_path(depfile.native());
  auto job_word = shell_variable("job", job.name);
  auto depfile_word = shell_variable("depfile_word", depfile.native());
  if (!depfile_ninja || !job_word || !depfile_word) return !depfile_ninja ? depfile_ninja.error() : !job_word ? job_word.error() : depfile_word.error();
  return "build" + *outputs + ": matbake " + manifest_path + (implicit.empty() ? "" : " |" + *inputs) + "\n" + *job_word +
         "  depfile_path = " + *depfile_ninja + "\n" + *depfile_word + "\n";
}

}  // namespace

Result<std::string> ninja_text(const Manifest& manifest, const Plan& plan, const fs::path& matbake, const fs::path& ninja_file) {
  if (Status s = check_depfile_paths(manifest, plan); !s) return s.error();  // each edge writes one
  auto manifest_path = ninja_path(manifest.file.native());
  // Named as Ninja names its manifest (the file in the folder it runs in), so that Ninja knows this
  // edge remakes it and reloads it before building.
  auto file_path = ninja_path(ninja_file.filename().native());
  if (!manifest_path || !file_path) return !manifest_path ? manifest_path.error() : file_path.error();
  std::string variables;
  for (const auto& [name, word] : {std::pair{"matbake", matbake.native()}, {"manifest", manifest.file.native()},
                                   {"output", manifest.output.native()}, {"plan_file", ninja_file.native()}}) {
    auto line = shell_variable(name, word);
    if (!line) return line.error();
    variables += line->substr(2);  // top level: not indented
  }
  // The manifest's path in a comment, as the shell would quote it (a line break was refused above).
  std::string text = "# Written by `matbake plan` (matbake " + std::string(version) + ") from " + shell_word(manifest.file.native()) +
                     ".\n# One edge per job; each edge's depfile adds what the job read. Written again by\n"
                     "# `matbake plan` when the manifest, or a folder a material rule scans, changes (the last edge).\n"
                     "ninja_required_version = 1.10\n\n" + variables + "\n";
  // Variables hold shell words ($matbake, $manifest, $job, ...): the command uses them unquoted.
  text += "rule matbake\n"
          "  command = $matbake build $manifest --output-dir $output --only $job --quiet --depfile $depfile_word\n"
          "  description = matbake $job\n"
          "  depfile = $depfile_path\n"
          "  deps = gcc\n"
          "  restat = 1\n\n";
  std::map<std::string, const Job*> by_name;
  for (const Job& job : plan.jobs) by_name[job.name] = &job;
  for (const Job& job : plan.jobs) {
    auto edge = job_edge(job, plan, by_name, *manifest_path);
    if (!edge) return edge.error();
    text += *edge;
  }
  std::vector<fs::path> scanned;
  for (const MaterialRule& rule : manifest.rules) add_unique(scanned, {rule.folder});
  auto folders = ninja_paths(scanned);
  if (!folders) return folders.error();
  // The file by its absolute path: never read as an option, wherever Ninja runs.
  text += "rule matbake_plan\n"
          "  command = $matbake plan $manifest --output-dir $output -o $plan_file --quiet\n"
          "  description = matbake plan $manifest\n"
          "  generator = 1\n\n"
          "build " + *file_path + ": matbake_plan " + *manifest_path + (scanned.empty() ? "" : " |" + *folders) + "\n";
  return text;
}

}  // namespace matbake::pipeline
