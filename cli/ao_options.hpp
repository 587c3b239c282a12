#pragma once
// The AO options of `bake-ao` and `export --ao-*`: ao::request_params() as flags.
#include <CLI/CLI.hpp>

#include <set>
#include <string>

#include "matbake/ao.hpp"
#include "matbake/export.hpp"

namespace matbake::cli {

struct AoSettings {
  ao::Request request;
  std::set<std::string> given;  // the parameters set on the command line
  std::string dump_texture;     // a folder for each texture as float EXR too (an output, so no manifest key)
};
// `prefix` goes before every option name ("" for bake-ao, "ao-" for export).
void add_ao_options(CLI::App& cmd, AoSettings& s, const std::string& prefix);
// The request, checked across its options; errors name the option as given on the command line.
Result<ao::Request> ao_request(const AoSettings& s, const std::string& prefix);
// One line per baked texture (and one per problem it counted), as bake-ao and export print them.
void print_texture_reports(const std::vector<bake_ao::TextureReport>& textures);

}  // namespace matbake::cli
