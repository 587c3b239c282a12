#pragma once
// Each command: setup_<name>() declares its options on the CLI11 app, run_<name>() calls the
// library and prints. Exit codes: 0 ok, 1 bad input or failed work, 2 bad usage.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "ao_options.hpp"
#include "material_sources.hpp"
#include "matbake/ao.hpp"
#include "matbake/bake_file.hpp"
#include "matbake/convert.hpp"
#include "matbake/export.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/preview.hpp"
#include "matbake/result.hpp"
#include "matbake/validate.hpp"
#include "matbake/workflow.hpp"

namespace matbake::cli {

// kViolations: validate found more flagged texels than --max-violations allows (a build can gate on it).
enum ExitCode { kOk = 0, kFailed = 1, kUsage = 2, kViolations = 3 };

struct GlobalOptions {
  bool json = false;
  bool quiet = false;
  int jobs = 0;  // 0: all cores
  std::string ocio_config;
  bool max_pixels_given = false;  // --max-pixels, which wins over a manifest's max_pixels
};

// A setting a library message mentions, as a flag: "--texture-rounding multiple-of-4", "--prune".
inline std::string flag_mention(const std::string& name, const std::string& value) {
  std::string flag = "--" + name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  if (value == "true") return flag;
  if (value == "false") return "--no-" + flag.substr(2);
  return value.empty() ? flag : flag + " " + value;
}

// Prints `matbake: error: <path>: <problem>` and returns the exit code the error calls for. The
// settings it mentions are spelt as flags, or (`build`, `plan`: the manifest's door) as keys.
inline int report_error(const Error& error, MentionSpelling spell = flag_mention) {
  std::cerr << "matbake: error: " << error.to_string(spell) << "\n";
  return error.usage ? kUsage : kFailed;
}

struct ConvertSettings {
  std::vector<std::string> inputs;
  std::string output;
  std::string out_dir;
  convert::Options options;
};
CLI::App* setup_convert(CLI::App& app, ConvertSettings& settings);
int run_convert(const ConvertSettings& settings, const GlobalOptions& global);

struct PreviewSettings {
  std::string output;
  SourceSettings sources;  // constants or textures, as pack reads them
  std::string materials;
  preview::Options options;  // model, size, gloss_sweep
  image::Encoding encoding;
};
CLI::App* setup_preview(CLI::App& app, PreviewSettings& settings);
int run_preview(const PreviewSettings& settings, const GlobalOptions& global);

struct PackSettings {
  std::string layout = "schuler";
  SourceSettings sources;
  OutputSettings output;
};
CLI::App* setup_pack(CLI::App& app, PackSettings& settings);
int run_pack(const PackSettings& settings, const GlobalOptions& global);

struct UnpackSettings {
  std::string layout = "schuler";
  std::vector<std::string> inputs;
  std::string out_dir;
  pack::MaterialOptions options;  // transfer, decode, bits, format
  image::Encoding encoding;
};
CLI::App* setup_unpack(CLI::App& app, UnpackSettings& settings);
int run_unpack(const UnpackSettings& settings, const GlobalOptions& global);

struct WorkflowSettings {
  std::string to;  // target layout
  std::string report;  // JSON file
  SourceSettings sources;
  OutputSettings output;
};
CLI::App* setup_workflow(CLI::App& app, WorkflowSettings& settings);
int run_workflow(const WorkflowSettings& settings, const GlobalOptions& global);

struct MaterialsSettings {
  std::string table;
};
CLI::App* setup_materials(CLI::App& app, MaterialsSettings& settings);
int run_materials(const MaterialsSettings& settings, const GlobalOptions& global);

struct ValidateSettings {
  SourceSettings sources;
  std::string material;
  std::string table;
  validate::Options options;
  std::string heatmap;
  std::string report;
};
CLI::App* setup_validate(CLI::App& app, ValidateSettings& settings);
int run_validate(const ValidateSettings& settings, const GlobalOptions& global);

struct BakeAoSettings {
  std::string scene;
  std::string output;
  std::string dump;
  bake_ao::Options options;  // its tree (bake_ao::request_tree); output and dump set at run
  std::vector<std::set<std::string>> given;
  std::string dump_texture;
};
CLI::App* setup_bake_ao(CLI::App& app, BakeAoSettings& settings);
int run_bake_ao(const BakeAoSettings& settings, const GlobalOptions& global);

struct BakeSettings {
  std::string low;
  std::string high;
  std::string cage;           // empty: extrusion
  std::string output;
  bake::FileOptions options;  // its tree (bake::request_tree); high, cage and output set at run
  std::vector<std::set<std::string>> given;
};
CLI::App* setup_bake(CLI::App& app, BakeSettings& settings);
int run_bake(const BakeSettings& settings, const GlobalOptions& global);

struct ExportSettings {
  std::string scene;
  std::string output;
  std::vector<std::string> materials;  // NAME=[LAYOUT:]FILE,FILE...
  pack::MaterialOptions material_options;  // transfer, decode: how those files are read
  exporter::Options options;              // its tree (exporter::request_tree): AO once any --ao-* is given
  std::vector<std::set<std::string>> given;
  std::string dump_texture;
  std::string report;
};
CLI::App* setup_export(CLI::App& app, ExportSettings& settings);
int run_export(const ExportSettings& settings, const GlobalOptions& global);

struct BuildSettings {
  std::string manifest;
  std::string output_dir;
  bool force = false;
  bool dry_run = false;
  bool keep_stale = false;
  bool prune = false;
  bool status = false;  // report how the jobs stand (after a cluster run); build nothing
  std::vector<std::string> only;
  std::string depfile;
  std::string stamp;
  std::string report;  // the report page; "" unless --report was given (or the manifest asks)
};
CLI::App* setup_build(CLI::App& app, BuildSettings& settings);
int run_build(const BuildSettings& settings, const GlobalOptions& global);

struct PlanSettings {
  std::string manifest;
  std::string output;
  std::string matbake;
  std::string output_dir;
  std::string format = "ninja";            // ninja | slurm
  bool dry_run = false;                    // slurm: print the sbatch commands, write nothing
  pipeline::ClusterOptions cluster;        // slurm: the flags given, over the manifest's [cluster]
  std::set<std::string> cluster_given;
};
CLI::App* setup_plan(CLI::App& app, PlanSettings& settings);
int run_plan(const PlanSettings& settings, const GlobalOptions& global);

struct InspectSettings {
  std::string path;
};
CLI::App* setup_inspect(CLI::App& app, InspectSettings& settings);
int run_inspect(const InspectSettings& settings, const GlobalOptions& global);

}  // namespace matbake::cli
