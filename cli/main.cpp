#include <tbb/global_control.h>

#include <memory>
#include <optional>

#include "commands.hpp"
#include "interrupt.hpp"
#include "matbake/image.hpp"
#include "matbake/near_names.hpp"
#include "matbake/version.hpp"

namespace {

// An option the command does not have, with the nearest ones it does: "unknown option --samplez;
// did you mean --samples or --sampler?".
std::optional<std::string> unknown_option(const CLI::App& app, const CLI::ParseError& e) {
  if (!dynamic_cast<const CLI::ExtrasError*>(&e)) return std::nullopt;
  for (const CLI::App* command : app.get_subcommands()) {
    std::vector<std::string> known;
    for (const CLI::App* scope : {command, &app}) {
      for (const CLI::Option* option : scope->get_options()) {
        for (const std::string& name : option->get_lnames()) known.push_back("--" + name);
      }
    }
    std::vector<std::string> args = command->remaining();
    const std::vector<std::string> passed_up = app.remaining();  // extras a subcommand hands to its parent
    args.insert(args.end(), passed_up.begin(), passed_up.end());
    for (std::string arg : args) {
      if (!arg.starts_with("--")) continue;
      arg = arg.substr(0, arg.find('='));
      return "unknown option " + arg + " for " + command->get_name() + matbake::did_you_mean(arg, known);
    }
  }
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace matbake::cli;
  CLI::App app{"matbake: material authoring and texture baking", "matbake"};
  app.set_version_flag("--version", std::string("matbake ") + matbake::version);
  app.require_subcommand(1, 1);
  app.fallthrough();  // global flags may also follow the command
  GlobalOptions global;
  app.add_flag("--json", global.json, "Print a machine-readable result on stdout");
  app.add_flag("-q,--quiet", global.quiet, "Print nothing but errors");
  app.add_option("-j,--jobs", global.jobs, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  std::uint64_t max_pixels = matbake::image::kDefaultMaxPixels;
  app.add_option("--max-pixels", max_pixels,
                 "Largest image read or made, in pixels (width x height); larger declared sizes are refused before\n"
                 "anything is allocated")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--ocio-config", global.ocio_config,
                 "OpenColorIO config for colour-space names (default: $OCIO, else the shipped presets/ocio/config.ocio)");

  ConvertSettings convert;
  CLI::App* convert_app = setup_convert(app, convert);
  PreviewSettings preview;
  CLI::App* preview_app = setup_preview(app, preview);
  PackSettings pack;
  CLI::App* pack_app = setup_pack(app, pack);
  UnpackSettings unpack;
  CLI::App* unpack_app = setup_unpack(app, unpack);
  WorkflowSettings workflow;
  CLI::App* workflow_app = setup_workflow(app, workflow);
  MaterialsSettings materials;
  CLI::App* materials_app = setup_materials(app, materials);
  ValidateSettings validate;
  CLI::App* validate_app = setup_validate(app, validate);
  BakeAoSettings bake_ao;
  CLI::App* bake_ao_app = setup_bake_ao(app, bake_ao);
  ExportSettings export_settings;
  CLI::App* export_app = setup_export(app, export_settings);
  BuildSettings build;
  CLI::App* build_app = setup_build(app, build);
  PlanSettings plan;
  CLI::App* plan_app = setup_plan(app, plan);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    if (auto unknown = unknown_option(app, e)) return report_error(matbake::Error{"", *unknown + " (see matbake --help)", true});
    std::string message = e.what();
    message = message.substr(0, message.find('\n'));
    return report_error(matbake::Error{"", message + " (see matbake --help)", true});
  }

  remove_temporary_files_on_interrupt();  // before any thread starts, so that all inherit the mask
  std::unique_ptr<tbb::global_control> threads;
  if (global.jobs > 0) {
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, global.jobs);
  }
  matbake::image::set_thread_count(global.jobs);
  matbake::image::set_max_pixels(max_pixels);

  // The library turns its dependencies' exceptions into errors at its edges; this is the last net,
  // so that nothing ends in abort (exit 134) without a line saying why.
  try {
    if (convert_app->parsed()) return run_convert(convert, global);
    if (preview_app->parsed()) return run_preview(preview, global);
    if (pack_app->parsed()) return run_pack(pack, global);
    if (unpack_app->parsed()) return run_unpack(unpack, global);
    if (workflow_app->parsed()) return run_workflow(workflow, global);
    if (materials_app->parsed()) return run_materials(materials, global);
    if (validate_app->parsed()) return run_validate(validate, global);
    if (bake_ao_app->parsed()) return run_bake_ao(bake_ao, global);
    if (export_app->parsed()) return run_export(export_settings, global);
    if (build_app->parsed()) return run_build(build, global);
    if (plan_app->parsed()) return run_plan(plan, global);
  } catch (const std::bad_alloc&) {
    return report_error(matbake::Error{"", "out of memory"});
  } catch (const std::exception& e) {
    std::string what = e.what();
    return report_error(matbake::Error{"", "internal error: " + what.substr(0, what.find('\n'))});
  }
  return kUsage;
}
