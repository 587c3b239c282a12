#include <tbb/global_control.h>

#include <charconv>
#include <functional>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "interrupt.hpp"
#include "matbake/image.hpp"
#include "matbake/join.hpp"
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

// A first word that is no command, with the nearest ones: "unknown command 'buidl'; did you mean build?".
std::optional<std::string> unknown_command(const CLI::App& app) {
  if (!app.get_subcommands().empty()) return std::nullopt;
  std::vector<std::string> known;
  for (const CLI::App* command : app.get_subcommands({})) known.push_back(command->get_name());
  for (const std::string& word : app.remaining()) {  // what no global option took
    if (word.starts_with("-")) continue;
    if (std::find(known.begin(), known.end(), word) != known.end()) return std::nullopt;
    const std::string near = matbake::did_you_mean(word, known);
    return "unknown command '" + matbake::escape_control(word) + "'" +
           (near.empty() ? " (commands: " + matbake::join(known, ", ") + ")" : near);
  }
  return std::nullopt;
}

// A whole number from `least` up, said in words when it is not one ("--jobs: a whole number, 0 or more").
CLI::Validator whole_number_from(long long least, const std::string& meaning) {
  return CLI::Validator(
      [least, meaning](std::string& text) -> std::string {
        long long value = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (ec == std::errc() && end == text.data() + text.size() && value >= least) return "";
        return "'" + text + "': " + meaning;
      },
      "");
}

// A command of the table main() dispatches from: its subcommand, and its run over the settings
// the subcommand's flags fill (kept alive by the run).
struct Command {
  CLI::App* app = nullptr;
  std::function<int(const matbake::cli::GlobalOptions&)> run;
};

template <class Settings>
Command command(CLI::App& app, CLI::App* (*setup)(CLI::App&, Settings&),
                int (*run)(const Settings&, const matbake::cli::GlobalOptions&)) {
  auto settings = std::make_shared<Settings>();
  return {setup(app, *settings), [settings, run](const matbake::cli::GlobalOptions& global) { return run(*settings, global); }};
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
  app.add_option("-j,--jobs", global.jobs, "Worker threads (default: all cores)")
      ->check(whole_number_from(0, "a count of worker threads, 0 (all cores) or more"));
  std::uint64_t max_pixels = matbake::image::kDefaultMaxPixels;
  app.add_option("--max-pixels", max_pixels,
                 "Largest image read or made, in pixels (width x height); larger declared sizes are refused before\n"
                 "anything is allocated (given here, it wins over a manifest's max_pixels)")
      ->capture_default_str()
      ->check(whole_number_from(1, "a count of pixels, 1 or more"));
  app.add_option("--ocio-config", global.ocio_config,
                 "OpenColorIO config for colour-space names (default: $OCIO, else the shipped presets/ocio/config.ocio)");

  // The commands, in --help's order: each one's settings filled by its flags, then its run.
  const std::vector<Command> commands = {
      command(app, setup_convert, run_convert),   command(app, setup_preview, run_preview),
      command(app, setup_pack, run_pack),         command(app, setup_unpack, run_unpack),
      command(app, setup_workflow, run_workflow), command(app, setup_materials, run_materials),
      command(app, setup_validate, run_validate), command(app, setup_bake_ao, run_bake_ao),
      command(app, setup_bake, run_bake),         command(app, setup_export, run_export),
      command(app, setup_build, run_build),
      command(app, setup_plan, run_plan),         command(app, setup_inspect, run_inspect),
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    if (auto unknown = unknown_option(app, e)) return report_error(matbake::Error{"", *unknown + " (see matbake --help)", true});
    if (auto unknown = unknown_command(app)) return report_error(matbake::Error{"", *unknown, true});
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
  global.max_pixels_given = app.count("--max-pixels") > 0;

  // The library turns its dependencies' exceptions into errors at its edges; this is the last net,
  // so that nothing ends in abort (exit 134) without a line saying why.
  try {
    for (const Command& c : commands) {
      if (c.app->parsed()) return c.run(global);
    }
  } catch (const std::bad_alloc&) {
    return report_error(matbake::Error{"", "out of memory"});
  } catch (const std::exception& e) {
    std::string what = e.what();
    return report_error(matbake::Error{"", "internal error: " + what.substr(0, what.find('\n'))});
  }
  return kUsage;
}
