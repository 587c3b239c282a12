#include "material_sources.hpp"

#include <filesystem>
#include <sstream>

#include "commands.hpp"
#include "matbake/encoding_params.hpp"
#include "params_cli.hpp"
#include "option_names.hpp"
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

Result<color::Transfer> parse_transfer(const std::string& name, const char* option) {
  auto t = color::transfer_from_name(name);
  if (!t) return Error{"", std::string(option) + " '" + name + "': use srgb, gamma2.2 or linear", true};
  return *t;
}

void add_source_options(CLI::App& cmd, SourceSettings& s, bool constant_size) {
  const auto sources = material::sources();
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const bool colour = sources[i].kind == material::SourceKind::color;
    cmd.add_option(option_of(sources[i].name), s.values[i],
                   std::string(sources[i].description) + (colour ? ": image, or linear grey / r,g,b" : ": image, or a value"))
        ->group("Sources");
  }
  cmd.add_option("--from", s.from, "Layout of packed input textures (the positional inputs), e.g. schuler")
      ->group("Sources");
  cmd.add_option("inputs", s.inputs, "Packed input textures, one per texture of --from")->group("Sources");
  cmd.add_option("--transfer", s.transfer, "Curve of 8-bit colour channels, read and written: srgb or gamma2.2")
      ->capture_default_str();
  cmd.add_option("--input-transfer", s.input_transfer,
                 "Curve of every colour input, overriding the rule (8-bit: --transfer; 16-bit, half, float: linear)");
  cmd.add_flag("--resize", s.resize, "Resample sources of different sizes to the largest (in linear light)");
  if (constant_size) cmd.add_option("--size", s.size, "WxH of the output when every source is a constant (default 1x1)");
}

Result<material::Maps> gather_sources(const SourceSettings& s) {
  auto transfer = parse_transfer(s.transfer, "--transfer");
  if (!transfer) return transfer.error();
  pack::LoadOptions options;
  options.authored = *transfer;
  options.resize = s.resize;
  if (!s.input_transfer.empty()) {
    auto t = parse_transfer(s.input_transfer, "--input-transfer");
    if (!t) return t.error();
    options.input = *t;
  }
  if (!s.size.empty()) {
    char x = 0;
    std::stringstream in(s.size);
    if (!(in >> options.width >> x >> options.height) || x != 'x' || options.width < 1 || options.height < 1 ||
        !in.eof()) {
      return Error{"", "--size '" + s.size + "': use WxH, e.g. 256x256", true};
    }
  }
  std::vector<pack::SourceInput> inputs;
  const auto sources = material::sources();
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::string& text = s.values[i];
    if (text.empty()) continue;
    auto input = pack::source_from_text(sources[i].name, text, {});
    if (!input) return Error{"", option_of(sources[i].name) + ": " + input.error().message, true};
    inputs.push_back(std::move(*input));
  }
  material::Maps maps;
  {
    SilencedStderr quiet;
    auto loaded = pack::load_sources(inputs, options);
    if (!loaded) return loaded.error();
    maps = std::move(loaded.value());
  }
  if (s.from.empty()) {
    if (!s.inputs.empty()) return Error{"", "input textures need --from LAYOUT to say what they hold", true};
    return maps;
  }
  // Packed inputs: unpack, then the per-source options take precedence.
  auto unpacked = read_packed(s.from, s.inputs, options.input, *transfer);
  if (!unpacked) return unpacked.error();
  if (!maps.maps.empty() && (maps.width != unpacked->width || maps.height != unpacked->height)) {
    return Error{s.inputs[0], "size differs from the other sources"};
  }
  for (auto& [name, map] : maps.maps) unpacked->maps[name] = std::move(map);
  return unpacked;
}

Result<material::Maps> read_packed(const std::string& layout_name, const std::vector<std::string>& files,
                                     std::optional<color::Transfer> input, color::Transfer authored) {
  auto layout = pack::find_layout(layout_name);
  if (!layout) return layout.error();
  SilencedStderr quiet;
  return pack::read_packed(*layout, {files.begin(), files.end()}, input, authored);
}

void add_output_options(CLI::App& cmd, OutputSettings& o, const std::string& what) {
  cmd.add_option("-o,--output", o.outputs,
                 "Output " + what + ": one per texture of the layout, in order, or one path with {texture}, "
                 "e.g. out/brick_{texture}.png")
      ->required();
  cmd.add_option("--bits", o.bits, "8, 16, half or float (default: 8; half for .exr). Colour is encoded with "
                                   "--transfer in 8-bit and linear otherwise");
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
  auto transfer = parse_transfer(inputs.transfer, "--transfer");
  if (!transfer) return transfer.error();
  pack::WriteRequest request{o.outputs, std::nullopt, *transfer, input_files(inputs), std::move(also), o.encoding};
  if (!o.bits.empty()) {
    request.type = image::sample_type_from_name(o.bits);
    if (!request.type) return Error{"", "--bits '" + o.bits + "': use 8, 16, half or float", true};
  }
  SilencedStderr quiet;
  auto written = pack::write_textures(layout, sources, request);
  if (!written) return written.error();
  return std::vector<std::string>(written->begin(), written->end());
}

}  // namespace matbake::cli
