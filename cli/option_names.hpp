#pragma once
// Options whose values are a library enum's names: the name is looked up in the module's table (a
// usage error lists the accepted names) and --help shows the library's default.
#include <CLI/CLI.hpp>

#include <string>

#include "matbake/enum_names.hpp"
#include "matbake/image.hpp"

namespace matbake::cli {

template <class E, std::size_t N>
CLI::Option* add_name_option(CLI::App& cmd, const std::string& flag, E& value, const NameTable<E, N>& table,
                             const std::string& description) {
  const std::string shown = flag.substr(flag.rfind(',') + 1);
  return cmd
      .add_option_function<std::string>(
          flag,
          [&value, &table, shown](const std::string& text) {
            const auto parsed = value_in(table, text);
            if (!parsed) throw CLI::ValidationError(shown, "'" + text + "': use " + names_in(table));
            value = *parsed;
          },
          description + ": " + names_in(table))
      ->default_str(std::string(name_in(table, value)));
}

// --png-compression: fast, default, small or a libdeflate level 0 to 12, into `level`.
inline CLI::Option* add_png_compression_option(CLI::App& cmd, int& level) {
  return cmd
      .add_option_function<std::string>(
          "--png-compression",
          [&level](const std::string& text) {
            const auto parsed = image::png_level_from_name(text);
            if (!parsed) throw CLI::ValidationError("--png-compression", "'" + text + "': use fast, default, small or 0 to 12");
            level = *parsed;
          },
          "Deflate effort of 8/16-bit PNG outputs: fast (level 1), default (6), small (12) or a level 0 to 12 "
          "(docs/performance.md has size and time per level)")
      ->default_str("default");
}

}  // namespace matbake::cli
