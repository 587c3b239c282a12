#pragma once
// Command-line flags made from a parameter description (matbake/params.hpp): each parameter as
// --<prefix><name>, its text decoded and checked by the description, --help showing its default
// (the request struct's) and accepted names. `given` collects the names set, for the tree's rules (finish_tree).
// An older name (Spec::aliases) is a hidden flag that works as the new one and says it was renamed.
#include <CLI/CLI.hpp>

#include <functional>
#include <iostream>
#include <set>
#include <stdexcept>
#include <string>

#include "matbake/join.hpp"
#include "matbake/params.hpp"

namespace matbake::cli {

// --help's placeholder per params::Kind.
inline constexpr const char* kTypeNames[] = {"", "INT", "NUMBER", "TEXT", "NAME", "VALUE"};

// Stores a checked value: nothing, or the problem.
using Setter = std::function<std::optional<std::string>(const params::Spec&, const params::Value&)>;

// The text of --FLAG VALUE, checked and stored: a problem is a usage error naming the flag.
inline void set_from_flag(const params::Spec& spec, const Setter& set, const std::string& flag, const std::string& text,
                          std::set<std::string>* given) {
  auto value = params::from_text(spec, text);
  std::optional<std::string> problem = value ? set(spec, *value) : value.error().message;
  if (problem) throw CLI::ValidationError(flag, "'" + text + "': " + *problem);
  if (given) given->insert(spec.name);
}

// Each of `specs` as a flag --PREFIXNAME (`only`: the names the command takes; empty: all), its
// default and accepted names in --help, its value stored by `set`.
inline void add_specs(CLI::App& cmd, const std::vector<const params::Spec*>& specs, const nlohmann::json& defaults,
                      const Setter& set, const std::string& prefix, const std::string& help_group,
                      std::set<std::string>* given, const std::set<std::string>& only = {}) {
  for (const params::Spec* spec : specs) {
    const params::Spec& p = *spec;
    if (p.manifest_only || (!only.empty() && !only.count(p.name))) continue;
    const std::string flag = params::flag_name(p, prefix);
    std::string help = p.help;
    if (p.kind == params::Kind::choice) help += ": " + params::type_text(p);
    for (const params::Condition& c : p.needs) {
      const std::string needed = params::flag_name(params::Spec{.name = c.name}, prefix);
      help += c.among ? " (with " + join(split(c.value, ','), " or ") + " among " + needed + ")"
                      : " (with " + needed + (c.value.empty() ? "" : " " + c.value) + ")";
    }
    if (p.kind == params::Kind::flag) {  // on by default: --no-NAME turns it off
      const bool on = defaults.at(p.name) == true;
      cmd.add_flag_callback(on ? "--no-" + flag.substr(2) : flag, [&p, set, given, on] {
           (void)set(p, params::Value(!on));
           if (given) given->insert(p.name);
         }, help)
          ->group(help_group);
      continue;
    }
    cmd.add_option_function<std::string>(
           flag, [&p, set, given, flag](const std::string& text) { set_from_flag(p, set, flag, text, given); }, help)
        ->type_name(kTypeNames[std::size_t(p.kind)])
        ->default_str(params::value_text(defaults.at(p.name)))
        ->group(help_group);
    for (const std::string& alias : p.aliases) {
      const std::string old = params::flag_name(params::Spec{.name = alias}, prefix);
      cmd.add_option_function<std::string>(old, [&p, set, given, old, flag](const std::string& text) {
           std::cerr << "matbake: note: " << old << " is now called " << flag << " (the old name still works)\n";
           set_from_flag(p, set, old, text, given);
         })->group("");
    }
  }
}

// A group's parameters as flags over `target`.
template <class T>
void add_params(CLI::App& cmd, const params::Group<T>& group, T& target, const std::string& prefix,
                const std::string& help_group, std::set<std::string>* given = nullptr,
                const std::set<std::string>& only = {}) {
  const Setter set = [&group, &target](const params::Spec& spec, const params::Value& v) {
    return params::apply(*group.find(spec.name), target, v);
  };
  add_specs(cmd, group.specs(), params::to_json(group, T{}), set, prefix, help_group, given, only);
}

// A request tree's parameters as flags over `root`: `given` gets one set per branch, `help_groups`
// is each branch's --help heading (one per branch: a tree that grows must be given its heading).
template <class Root>
void add_tree(CLI::App& cmd, const params::Tree<Root>& tree, Root& root, std::vector<std::set<std::string>>& given,
              const std::vector<std::string>& help_groups) {
  if (help_groups.size() != tree.size()) throw std::logic_error("a --help heading per branch of the request tree");
  given.assign(tree.size(), {});
  for (std::size_t i = 0; i < tree.size(); ++i) {
    const params::Branch<Root>& b = tree[i];
    const Setter set = [&b, &root](const params::Spec& spec, const params::Value& v) { return b.apply(root, spec, v); };
    add_specs(cmd, b.specs, b.values(Root{}), set, b.flag_prefix, help_groups.at(i), &given[i]);
  }
}

// The command line's spelling of a group's parameters: --PREFIXNAME, and "--NAME VALUE" (a flag at
// true is the flag alone).
inline params::Spelling flag_spelling(std::vector<std::string> prefixes) {
  return [prefixes = std::move(prefixes)](std::size_t group, const params::Spec& spec, const std::string* value) {
    const std::string flag = params::flag_name(spec, prefixes.at(group));
    return value && !(spec.kind == params::Kind::flag && *value == "true") ? flag + " " + *value : flag;
  };
}

template <class Root>
params::Spelling tree_flag_spelling(const params::Tree<Root>& tree) {
  std::vector<std::string> prefixes;
  for (const params::Branch<Root>& b : tree) prefixes.push_back(b.flag_prefix);
  return flag_spelling(std::move(prefixes));
}

// The rules across a tree and each branch's own, errors naming the flags.
template <class Root>
Status finish_tree(const params::Tree<Root>& tree, const Root& root, const std::vector<std::set<std::string>>& given) {
  return params::finish_tree(tree, root, given, tree_flag_spelling(tree));
}

}  // namespace matbake::cli
