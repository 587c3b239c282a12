#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <map>

#include "commands.hpp"
#include "matbake/encoding_params.hpp"
#include "params_cli.hpp"
#include "matbake/convert_params.hpp"
#include "silenced_stderr.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

std::string describe_channels(const convert::Report& r) {
  static const char* const kLayouts[] = {"", "gray", "gray+alpha", "RGB", "RGBA"};
  return kLayouts[r.channels];
}

// -o OUT or --out-dir DIR, checked: the list of outputs, one per input.
Result<std::vector<fs::path>> output_paths(const ConvertSettings& s, bool target_is_linear) {
  if (s.output.empty() == s.out_dir.empty()) {
    return Error{"", "convert needs -o OUT (one input) or --out-dir DIR", true};
  }
  if (!s.output.empty()) {
    if (s.inputs.size() != 1) return Error{"", "-o takes one input; use --out-dir DIR for several", true};
    const fs::path out(s.output);
    if (!s.options.format.empty() && out.extension() != "." + s.options.format) {
      return Error{s.output, "--format " + s.options.format + " disagrees with the output's extension", true};
    }
    return std::vector<fs::path>{out};
  }
  std::vector<fs::path> outputs;
  std::map<fs::path, std::string> taken;
  for (const std::string& in : s.inputs) {
    outputs.push_back(convert::output_path_in_folder(in, s.out_dir, s.options.format, target_is_linear));
    if (auto [it, fresh] = taken.emplace(outputs.back(), in); !fresh) {
      return Error{in, "would be written to " + outputs.back().string() + " as " + it->second + " is", true};
    }
  }
  return outputs;
}

}  // namespace

CLI::App* setup_convert(CLI::App& app, ConvertSettings& s) {
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Re-encode images between sRGB (IEC 61966-2-1, exact), gamma 2.2 and linear, or OCIO colour spaces.\n"
      "Alpha is never transferred and stays unassociated. NaN/Inf samples are rejected.");
  cmd->add_option("inputs", s.inputs, "Input images: PNG, TIFF, JPEG, EXR, ... (1 to 4 channels)")->required();
  CLI::Option* out = cmd->add_option("-o,--output", s.output, "Output file (.exr, .png, .tif), for one input");
  CLI::Option* dir = cmd->add_option("--out-dir", s.out_dir, "Output folder (created if missing): <input name>.<format> per input");
  out->excludes(dir);
  add_params(*cmd, convert::options_params(), s.options, "", "Options");
  add_params(*cmd, image::encoding_params(), s.options.encoding, "", "Options");
  return cmd;
}

int run_convert(const ConvertSettings& settings, const GlobalOptions& global) {
  convert::Options options = settings.options;
  options.ocio_config = global.ocio_config;

  auto plan = convert::plan_conversion(options);
  if (!plan) return report_error(plan.error());
  auto outputs = output_paths(settings, plan->target_is_linear);
  if (!outputs) return report_error(outputs.error());

  nlohmann::json results = nlohmann::json::array();
  int exit_code = kOk;
  std::size_t failed = 0;
  for (std::size_t i = 0; i < settings.inputs.size(); ++i) {
    const auto start = std::chrono::steady_clock::now();
    auto report = [&] {
      SilencedStderr quiet;
      return convert::convert_file(*plan, settings.inputs[i], (*outputs)[i], options);
    }();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!report) {
      exit_code = std::max(exit_code, report_error(report.error()));
      ++failed;
      results.push_back({{"input", settings.inputs[i]}, {"error", report.error().to_string()}});
      continue;
    }
    const convert::Report& r = *report;
    if (!global.quiet && !global.json) {
      std::cout << r.input.string() << " -> " << r.output.string() << " (" << r.width << "x" << r.height << " "
                << describe_channels(r) << ", " << options.from << " " << image::sample_type_name(r.input_type)
                << " -> " << options.to << " " << image::sample_type_name(r.output_type) << ")\n";
    }
    results.push_back({{"input", r.input.string()},
                       {"output", r.output.string()},
                       {"width", r.width},
                       {"height", r.height},
                       {"channels", r.channels},
                       {"input_type", image::sample_type_name(r.input_type)},
                       {"output_type", image::sample_type_name(r.output_type)},
                       {"milliseconds", ms}});
  }
  if (failed > 0 && settings.inputs.size() > 1) {
    std::cerr << "matbake: " << failed << " of " << settings.inputs.size() << " conversions failed\n";
  }
  if (global.json) {
    nlohmann::json out = {{"command", "convert"},
                          {"from", options.from},
                          {"to", options.to},
                          {"options", params::to_json(convert::options_params(), options)},
                          {"results", results}};
    if (!plan->ocio_source.empty()) out["ocio_config"] = plan->ocio_source;
    std::cout << out.dump(2) << "\n";
  }
  return exit_code;
}

}  // namespace matbake::cli
