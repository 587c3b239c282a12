#pragma once
// Command-line flags made from a parameter description (matbake/params.hpp): each parameter as
// --<prefix><name>, its text decoded and checked by the description, --help showing its default
// (the request struct's) and accepted names. `given` collects the names set, for params::finish.
// An older name (Spec::aliases) is a hidden flag that works as the new one and says it was renamed.
#include <CLI/CLI.hpp>

#include <set>
#include <string>

#include "matbake/params.hpp"

namespace matbake::cli {

// --help's placeholder per params::Kind.
inline constexpr const char* kTypeNames[] = {"", "INT", "NUMBER", "TEXT", "NAME", "VALUE"};

// The text of --FLAG VALUE, checked and stored: a problem is a usage error naming the flag.
template <class T>
void set_from_flag(const params::Param<T>& p, T& target, const std::string& flag, const std::string& text,
                   std::set<std::string>* given) {
  auto value = params::from_text(p.spec, text);
  std::optional<std::string> problem = value ? params::apply(p, target, *value) : value.error().message;
  if (problem) throw CLI::ValidationError(flag, "'" + text + "': " + *problem);
  if (given) given->insert(p.spec.name);
}

// `only`: the names of the group's parameters the command takes (empty: all).
template <class T>
void add_params(CLI::App& cmd, const params::Group<T>& group, T& target, const std::string& prefix,
                const std::string& help_group, std::set<std::string>* given = nullptr,
                const std::set<std::string>& only = {}) {
  const nlohmann::json defaults = params::to_json(group, T{});
  for (const params::Param<T>& p : group.params) {
    if (p.spec.manifest_only || (!only.empty() && !only.count(p.spec.name))) continue;
    const std::string flag = params::flag_name(p.spec, prefix);
    std::string help = p.spec.help;
    if (p.spec.kind == params::Kind::choice) help += ": " + params::type_text(p.spec);
    if (!p.spec.needs.empty()) help += " (with --" + prefix + p.spec.needs + ")";
    if (p.spec.kind == params::Kind::flag) {  // on by default: --no-NAME turns it off
      const bool on = defaults.at(p.spec.name) == true;
      cmd.add_flag_callback(on ? "--no-" + flag.substr(2) : flag, [&p, &target, given, on] {
           (void)params::apply(p, target, params::Value(!on));
           if (given) given->insert(p.spec.name);
         }, help)
          ->group(help_group);
      continue;
    }
    const nlohmann::json& d = defaults.at(p.spec.name);
    cmd.add_option_function<std::string>(
           flag, [&p, &target, given, flag](const std::string& text) { set_from_flag(p, target, flag, text, given); },
           help)
        ->type_name(kTypeNames[std::size_t(p.spec.kind)])
        ->default_str(params::value_text(d))
        ->group(help_group);
    for (const std::string& alias : p.spec.aliases) {
      const std::string old = params::flag_name(params::Spec{.name = alias}, prefix);
      cmd.add_option_function<std::string>(old, [&p, &target, given, old, flag](const std::string& text) {
           std::cerr << "matbake: note: " << old << " is now called " << flag << " (the old name still works)\n";
           set_from_flag(p, target, old, text, given);
         })->group("");
    }
  }
}

// The command line's spelling of a group's parameters: --PREFIXNAME, and "--NAME VALUE".
inline params::Spelling flag_spelling(std::vector<std::string> prefixes) {
  return [prefixes = std::move(prefixes)](std::size_t group, const params::Spec& spec, const std::string* value) {
    const std::string flag = params::flag_name(spec, prefixes.at(group));
    return value ? flag + " " + *value : flag;
  };
}

// The rules within a group, errors naming the flags.
template <class T>
Status finish_params(const params::Group<T>& group, const T& target, const std::set<std::string>& given,
                     const std::string& prefix) {
  return params::finish(group, target, given, flag_spelling({prefix}));
}

}  // namespace matbake::cli
