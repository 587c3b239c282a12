#pragma once
// What the AO flags of `bake-ao` and `export --ao-*` need beside their tree: --dump-texture (an
// output folder, so no manifest key) and the printed texture lines.
#include <CLI/CLI.hpp>

#include <string>

#include "matbake/ao.hpp"
#include "matbake/export.hpp"

namespace matbake::cli {

// `prefix` goes before the option name ("" for bake-ao, "ao-" for export).
void add_dump_texture(CLI::App& cmd, std::string& folder, const std::string& prefix, const std::string& help_group);
// The folder into the request's texture bake; an error when there is none.
Status set_dump_texture(ao::Request& request, const std::string& folder, const std::string& prefix);
// One line per baked texture (and one per problem it counted), as bake-ao and export print them.
void print_texture_reports(const std::vector<bake_ao::TextureReport>& textures);

}  // namespace matbake::cli
