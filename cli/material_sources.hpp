#pragma once
// What pack, unpack and workflow share: source maps given as options (--kd FILE or --kd 0.5,0.4,0.3)
// or as packed textures of a layout (--from LAYOUT IN...), and writing a layout's textures.
#include <CLI/CLI.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "matbake/pack.hpp"

namespace matbake::cli {

struct SourceSettings {
  std::array<std::string, 9> values;  // by material::sources() index: a file, or numbers
  std::string from;                   // layout of the packed inputs
  std::vector<std::string> inputs;    // packed inputs, one per texture of `from`
  std::string transfer = "srgb";      // 8-bit colour, read and written
  std::string input_transfer;         // overrides the rule for colour inputs
  bool resize = false;
  std::string size;                   // WxH when every source is a constant
};
// `constant_size`: also --size WxH (the size of an output made of constants alone).
void add_source_options(CLI::App& cmd, SourceSettings& s, bool constant_size = true);
Result<material::Maps> gather_sources(const SourceSettings& s);
// The source maps in `files`, the textures of layout `layout_name` in order: colour decoded with
// `input` when given, else `authored` for 8-bit files and linear for the rest.
Result<material::Maps> read_packed(const std::string& layout_name, const std::vector<std::string>& files,
                                     std::optional<color::Transfer> input, color::Transfer authored);

struct OutputSettings {
  std::vector<std::string> outputs;  // one per layout texture, or one with {texture}
  std::string bits;                  // 8, 16, half, float; default 8 (half for .exr)
  image::Encoding encoding;
};
void add_output_options(CLI::App& cmd, OutputSettings& o, const std::string& what);
// Writes the layout's textures; returns the paths written. An output that is one of the inputs
// is refused before anything is written.
// The files among the sources (numbers left out), for the rule that no output overwrites them.
std::vector<std::filesystem::path> input_files(const SourceSettings& inputs);
Result<std::vector<std::string>> write_textures(const pack::Layout& layout, const material::Maps& sources,
                                                const OutputSettings& o, const SourceSettings& inputs,
                                                std::vector<NamedOutput> also = {});
Result<color::Transfer> parse_transfer(const std::string& name, const char* option);

}  // namespace matbake::cli
