#pragma once
// Command-line flags made from a parameter description (matbake/params.hpp): each parameter as
// --<prefix><name>, its text decoded and checked by the description, --help showing its default
// (the request struct's) and accepted names. `given` collects the names set, for params::finish.
#include <CLI/CLI.hpp>

#include <set>
#include <string>

#include "matbake/params.hpp"

namespace matbake::cli {

// --help's placeholder per params::Kind.
inline constexpr const char* kTypeNames[] = {"", "INT", "NUMBER", "TEXT", "NAME", "VALUE"};

template <class T>
void add_params(CLI::App& cmd, const params::Group<T>& group, T& target, const std::string& prefix,
                const std::string& help_group, std::set<std::string>* given = nullptr) {
  const nlohmann::json defaults = params::to_json(group, T{});
  for (const params::Param<T>& p : group.params) {
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
           flag,
           [&p, &target, given, flag](const std::string& text) {
             auto value = params::from_text(p.spec, text);
             std::optional<std::string> problem = value ? params::apply(p, target, *value) : value.error().message;
             if (problem) throw CLI::ValidationError(flag, "'" + text + "': " + *problem);
             if (given) given->insert(p.spec.name);
           },
           help)
        ->type_name(kTypeNames[std::size_t(p.spec.kind)])
        ->default_str(params::value_text(d))
        ->group(help_group);
  }
}

// The rules across parameters, errors naming the flags.
template <class T>
Status finish_params(const params::Group<T>& group, const T& target, const std::set<std::string>& given,
                     const std::string& prefix) {
  return params::finish(group, target, given, [&](const std::string& name) {
    const params::Param<T>* p = group.find(name);
    return p ? params::flag_name(p->spec, prefix) : name;
  });
}

}  // namespace matbake::cli
