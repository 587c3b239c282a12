#pragma once
// What pack, unpack and workflow share: source maps given as options (--kd FILE or --kd 0.5,0.4,0.3)
// or as packed textures of a layout (--from LAYOUT IN...), and writing a layout's textures.
#include <CLI/CLI.hpp>

#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "matbake/pack.hpp"

namespace matbake::cli {

struct SourceSettings {
  std::array<std::string, material::kSourceCount> values;  // by material::sources() index: a file, or numbers
  std::string from;                   // layout of the packed inputs
  std::vector<std::string> inputs;    // packed inputs, one per texture of `from`
  pack::MaterialOptions options;      // those of pack::material_params() the command takes
};
// The source flags, --from and the packed inputs, and `params`: the names of the
// pack::material_params() the command takes.
void add_source_options(CLI::App& cmd, SourceSettings& s, const std::set<std::string>& params);
Result<material::Maps> gather_sources(const SourceSettings& s);

struct OutputSettings {
  std::vector<std::string> outputs;  // one per layout texture, or one with {texture}
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

}  // namespace matbake::cli
