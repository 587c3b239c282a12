#pragma once
// The AO options of `bake-ao` and `export --ao-*`: every field of ao::Request, its defaults the
// library's.
#include <CLI/CLI.hpp>

#include <string>

#include "matbake/ao.hpp"
#include "matbake/export.hpp"

namespace matbake::cli {

struct AoSettings {
  ao::Request request;
  std::string into{ao::into_attribute_name(request.into)};
  std::string existing_colors{ao::into_existing_colors_name(request.into)};
  // Texture bakes (bake-ao only, for now): on when `texture` (a size) is given.
  std::string texture;
  ao::TextureRequest texture_request;
  std::string existing_occlusion{texture_request.multiply_existing ? "multiply" : "replace"};
};
// `prefix` goes before every option name ("" for bake-ao, "ao-" for export); `textures` adds the
// texture bake's options.
void add_ao_options(CLI::App& cmd, AoSettings& s, const std::string& prefix, bool textures = false);
// The request, checked; errors name the option as given on the command line.
Result<ao::Request> ao_request(const AoSettings& s, const std::string& prefix);
// One line per baked texture (and one per problem it counted), as bake-ao and export print them.
void print_texture_reports(const std::vector<exporter::TextureReport>& textures);

}  // namespace matbake::cli
