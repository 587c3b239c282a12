#include <algorithm>
#include <cctype>

#include "matbake/ao_params.hpp"
#include "matbake/bake_params.hpp"
#include "matbake/cluster.hpp"
#include "matbake/encoding_params.hpp"
#include "matbake/export_params.hpp"
#include "matbake/material_params.hpp"
#include "matbake/pipeline_params.hpp"
#include "matbake/validate_params.hpp"

namespace matbake::pipeline {

const params::Group<ValidationRules>& validation_params() {
  using params::Spec;
  static const params::Group<ValidationRules> group{{
      params::flag<ValidationRules>(Spec{.name = "enabled",
                                         .help = "Validate the material (its report OUT/materials/NAME.validation.json)",
                                         .example = "false",
                                         .manifest_only = true},
                                    [](auto& r) -> auto& { return r.enabled; }),
      params::flag<ValidationRules>(Spec{.name = "heatmap",
                                         .help = "Also write the validation's heatmap, OUT/materials/NAME_validation.png "
                                                 "(as the validate command's heatmap)",
                                         .example = "true",
                                         .manifest_only = true},
                                    [](auto& r) -> auto& { return r.heatmap; }),
  }};
  return group;
}

const params::Group<SceneSpec>& scene_params() {
  using params::Spec;
  static const params::Group<SceneSpec> group{{
      params::flag<SceneSpec>(Spec{.name = "match_names",
                                   .help = "glTF materials named like a manifest material get it, besides those "
                                           "`materials` assigns",
                                   .example = "false",
                                   .manifest_only = true},
                              [](auto& s) -> auto& { return s.match_names; }),
  }};
  return group;
}

const params::Group<SceneBake>& bake_source_params() {
  using params::Spec;
  static const params::Group<SceneBake> group{{
      params::text<SceneBake>(Spec{.name = "from",
                                   .help = "The high-poly glTF (.gltf or .glb) whose maps are baked onto the scene "
                                           "before it is exported (as matbake bake's); required in a bake table",
                                   .example = "sculpts/hero_high.glb",
                                   .manifest_only = true},
                              [](auto& b) -> auto& { return b.from; }),
      params::text<SceneBake>(Spec{.name = "cage",
                                   .help = "A cage mesh (.gltf or .glb): the scene's input with its vertices moved "
                                           "out; the rays start on it and head for the input (as matbake bake's cage)",
                                   .example = "sculpts/hero_cage.glb",
                                   .manifest_only = true},
                              [](auto& b) -> auto& { return b.cage_file; }),
  }};
  return group;
}

const params::Tree<MaterialSpec>& material_tree() {
  static const params::Tree<MaterialSpec> tree{
      params::branch<MaterialSpec>(pack::material_params(), "", "", [](auto& m) -> auto& { return m.options; }),
      params::branch<MaterialSpec>(image::encoding_params(), "", "", [](auto& m) -> auto& { return m.encoding; }),
      params::branch<MaterialSpec>(validation_params(), "validate", "", [](auto& m) -> auto& { return m.validation; }),
      params::branch<MaterialSpec>(validate::options_params(), "validate", "",
                                   [](auto& m) -> auto& { return m.validation.options; }),
  };
  return tree;
}

const params::Tree<SceneSpec>& scene_tree() {
  static const params::Tree<SceneSpec> tree = [] {
    params::Tree<SceneSpec> t{params::branch<SceneSpec>(scene_params(), "", "", [](auto& s) -> auto& { return s; })};
    for (params::Branch<SceneSpec>& b :
         params::subtree<SceneSpec>(exporter::request_tree(), [](auto& s) -> auto& { return s.options; })) {
      t.push_back(std::move(b));
    }
    // A scene bakes when its own table has `bake` (read_scene); the top level's gives defaults.
    const params::OptionalPart<SceneSpec, SceneBake> bake{&SceneSpec::bake};
    const auto baking = [](const SceneSpec& s) { return s.bake.has_value(); };
    t.push_back(params::branch<SceneSpec>(bake_source_params(), "bake", "", bake, baking));
    t.push_back(params::branch<SceneSpec>(bake::request_params(), "bake", "",
                                          [bake](auto& s) -> auto& { return bake(s).request; }, baking));
    t.push_back(params::branch<SceneSpec>(ao::estimator_params(), "bake.ao", "",
                                          [bake](auto& s) -> auto& { return bake(s).request.occlusion; }, baking));
    return t;
  }();
  return tree;
}

namespace {

// Text passed to sbatch as one argument: only the characters Slurm's names and times use, so that a
// typing slip is refused here and not by sbatch on the cluster.
params::Param<ClusterOptions> sbatch_text(params::Spec spec, std::string ClusterOptions::*field, std::string_view extra,
                                          std::string what) {
  params::Param<ClusterOptions> p = params::text<ClusterOptions>(std::move(spec), [field](auto& o) -> auto& { return o.*field; });
  p.set = [field, extra, what](ClusterOptions& o, const params::Value& v) -> std::optional<std::string> {
    const std::string& text = std::get<std::string>(v);
    const bool fits = std::all_of(text.begin(), text.end(), [&](char c) {
      return std::isdigit(static_cast<unsigned char>(c)) || extra.find(c) != std::string_view::npos;
    });
    if (!fits) return what;
    o.*field = text;
    return std::nullopt;
  };
  return p;
}

constexpr std::string_view kNameCharacters = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_-.,";

}  // namespace

const params::Group<ClusterOptions>& cluster_params() {
  using params::Spec;
  static const params::Group<ClusterOptions> group{{
      sbatch_text(Spec{.name = "partition", .help = "Slurm partition of every job (unset: the cluster's default)", .example = "batch"},
                  &ClusterOptions::partition, kNameCharacters, "letters, digits, '_', '-', '.' and ',' only"),
      sbatch_text(Spec{.name = "account", .help = "Slurm account the jobs are charged to (unset: yours)", .example = "art"},
                  &ClusterOptions::account, kNameCharacters, "letters, digits, '_', '-', '.' and ',' only"),
      sbatch_text(Spec{.name = "time_limit",
                       .help = "Time limit of each job, as sbatch --time takes it: MM, MM:SS, HH:MM:SS or D-HH:MM "
                               "(unset: the partition's)",
                       .example = "30:00"},
                  &ClusterOptions::time_limit, ":-", "minutes, MM:SS, HH:MM:SS or D-HH:MM:SS"),
      params::integer<ClusterOptions>(Spec{.name = "array_throttle",
                                           .help = "At most this many material jobs running at once (0: no limit; "
                                                   "as sbatch --array=...%N)",
                                           .min = 0,
                                           .max = 1e6,
                                           .example = "16"},
                                      [](auto& o) -> auto& { return o.array_throttle; }),
      params::integer<ClusterOptions>(Spec{.name = "memory_mb",
                                           .help = "Memory of each job in MB (0: the memory model's estimate of what "
                                                   "the job holds, docs/cluster.md)",
                                           .min = 0,
                                           .max = 1e8,
                                           .example = "4096"},
                                      [](auto& o) -> auto& { return o.memory_mb; }),
      params::integer<ClusterOptions>(Spec{.name = "material_memory_mb",
                                           .help = "Memory of the material jobs in MB, over memory_mb (0: memory_mb's)",
                                           .min = 0,
                                           .max = 1e8,
                                           .example = "2048"},
                                      [](auto& o) -> auto& { return o.material_memory_mb; }),
      params::integer<ClusterOptions>(Spec{.name = "scene_memory_mb",
                                           .help = "Memory of each scene job in MB, over memory_mb (0: memory_mb's)",
                                           .min = 0,
                                           .max = 1e8,
                                           .example = "8192"},
                                      [](auto& o) -> auto& { return o.scene_memory_mb; }),
      params::integer<ClusterOptions>(Spec{.name = "cpus",
                                           .help = "Cores of each job (sbatch --cpus-per-task; the job runs with "
                                                   "as many worker threads); plan's thread count sets it too",
                                           .min = 1,
                                           .max = 4096,
                                           .example = "4",
                                           .manifest_only = true},
                                      [](auto& o) -> auto& { return o.cpus; }),
  }};
  return group;
}

}  // namespace matbake::pipeline
