#pragma once
// Options whose values are a library enum's names: the name is looked up in the module's table (a
// usage error lists the accepted names) and --help shows the library's default.
#include <CLI/CLI.hpp>

#include <string>

#include "matbake/enum_names.hpp"

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

}  // namespace matbake::cli
