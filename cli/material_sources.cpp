#include "material_sources.hpp"

#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "matbake/encoding_params.hpp"
#include "params_cli.hpp"
#include "matbake/material_params.hpp"
#include "silenced_stderr.hpp"

namespace fs = std::filesystem;

namespace matbake::cli {
namespace {

std::string option_of(std::string_view source) {
  std::string name(source);
  std::replace(name.begin(), name.end(), '_', '-');
  return "--" + name;
}

}  // namespace

void add_source_options(CLI::App& cmd, SourceSettings& s, const std::set<std::string>& params) {
  const auto sources = material::sources();
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const char* forms = sources[i].kind == material::SourceKind::color    ? ": image, or linear grey / r,g,b"
                        : sources[i].kind == material::SourceKind::vector ? ": image, or its stored r,g,b"
                                                                          : ": image, or a value";
    cmd.add_option(option_of(sources[i].name), s.values[i], std::string(sources[i].description) + forms)
        ->group("Sources");
  }
  cmd.add_option("--from", s.from, "Layout of packed input textures (the positional inputs), e.g. schuler")
      ->group("Sources");
  cmd.add_option("inputs", s.inputs, "Packed input textures, one per texture of --from")->group("Sources");
  add_params(cmd, pack::material_params(), s.options, "", "Options", nullptr, params);
}

Result<material::Maps> gather_sources(const SourceSettings& s) {
  std::vector<pack::SourceInput> inputs;
  const auto sources = material::sources();
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::string& text = s.values[i];
    if (text.empty()) continue;
    auto input = pack::source_from_text(sources[i].name, text, {});
    if (!input) return Error{"", option_of(sources[i].name) + ": " + input.error().message, true};
    inputs.push_back(std::move(*input));
  }
  if (s.from.empty() && !s.inputs.empty()) {
    return Error{"", "input textures need --from LAYOUT to say what they hold", true};
  }
  std::optional<pack::Layout> packed;
  if (!s.from.empty()) {
    auto layout = pack::find_layout(s.from);
    if (!layout) return layout.error();
    packed = std::move(*layout);
  }
  for (const std::string& note : pack::decode_overrides(inputs, s.options)) {
    std::cerr << "matbake: warning: " << escape_control(note) << "\n";
  }
  SilencedStderr quiet;
  return pack::load_material(inputs, packed ? &*packed : nullptr, {s.inputs.begin(), s.inputs.end()}, s.options);
}

void add_output_options(CLI::App& cmd, OutputSettings& o, const std::string& what) {
  cmd.add_option("-o,--output", o.outputs,
                 "Output " + what + ": one per texture of the layout, in order, or one path with {texture}, "
                 "e.g. out/brick_{texture}.png")
      ->required();
  add_params(cmd, image::encoding_params(), o.encoding, "", "Options");
}

std::vector<std::filesystem::path> input_files(const SourceSettings& inputs) {
  std::vector<std::filesystem::path> files(inputs.inputs.begin(), inputs.inputs.end());
  for (const std::string& v : inputs.values) {
    if (auto source = v.empty() ? Result<pack::SourceInput>(Error{}) : pack::source_from_text("", v, {}); source && !source->file.empty()) {
      files.push_back(source->file);
    }
  }
  return files;
}

Result<std::vector<std::string>> write_textures(const pack::Layout& layout, const material::Maps& sources,
                                                const OutputSettings& o, const SourceSettings& inputs,
                                                std::vector<NamedOutput> also) {
  for (const std::string& output : o.outputs) {
    if (auto problem = inputs.options.bits ? image::sample_type_problem(output, *inputs.options.bits) : std::nullopt) {
      return Error{"--bits", *problem + " (" + output + ")", true};
    }
  }
  const pack::WriteRequest request{o.outputs,           inputs.options.bits, inputs.options.transfer,
                                   input_files(inputs), std::move(also),     o.encoding};
  SilencedStderr quiet;
  auto written = pack::write_textures(layout, sources, request);
  if (!written) return written.error();
  return std::vector<std::string>(written->begin(), written->end());
}

}  // namespace matbake::cli
