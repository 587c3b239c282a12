#pragma once
// One description per request: each parameter's name, type, range or names, help and an example,
// with the field it fills. The command line's flags (cli/params_cli.hpp), the manifest's keys
// (pipeline/manifest.cpp), the --json echo and build stamps (to_json) and the docs' tables
// (markdown_table, checked by a test) are all made from it, so a parameter is spelt, decoded,
// checked and documented once. Defaults are the request struct's own (T{}).
// pbrt-v4's ParameterDictionary (typed look-ups, origins in errors, unknown names reported) and
// KTX-Software's self-checking option groups were the models.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "matbake/enum_names.hpp"
#include "matbake/result.hpp"

namespace matbake::params {

// A parameter another one applies with, and (when not empty) the value it must have; with `among`,
// `value` is names (comma-separated) one of which the parameter's list (comma-separated: a bake's
// maps) must hold: green acts only on the normal or bent-normal map.
struct Condition {
  std::string name;
  std::string value;
  bool among = false;
};

// A value as a door gives it: the command line's text is turned into one by from_text, a
// manifest's TOML value by its type.
using Value = std::variant<bool, std::int64_t, double, std::string>;

enum class Kind {
  flag,             // true or false; on the command line a flag without a value
  integer,          // within [min, max]
  number,           // within [min, max] (an integer is taken as a number)
  text,             // any string; the parameter's set() judges it
  choice,           // one of `choices`
  integer_or_text,  // an integer or a name (a PNG level or "small"; a size 1024 or "2048x1024")
};

// What both doors and the docs need to know of a parameter, whatever it fills.
struct Spec {
  std::string name;                  // the manifest's key; the flag is --name with '-' for '_'
  Kind kind = Kind::text;
  std::string help;                  // one line, no trailing period
  std::vector<std::string> choices;  // choice: the accepted names
  double min = 0, max = 0;           // integer, number: the range (none when both are 0; max may be ∞)
  bool above_min = false;            // the range excludes min (a distance above 0)
  std::string example;               // a value other than the default, as a flag takes it
  std::vector<std::string> aliases;  // older manifest keys, still read, with a note
  // Rules across parameters, run at both doors by check_rules with one message each (a door only
  // spells the names): `needs` are the parameters this one applies with, in its own group or
  // another of the request: given (texcoord: texture), set to a value (colour_quality:
  // texture_format = ktx2, colour_codec = etc1s), or a list holding a value (green: normal or
  // bent_normal among maps). `excludes`: parameters it cannot be given with.
  std::vector<Condition> needs;
  std::vector<std::string> excludes;
  bool manifest_only = false;        // a manifest key with no flag (a build's own setting)
  // Read only where a material's own textures are written (bits, format), not where its maps are
  // loaded: a scene's stamp leaves it out.
  bool written_only = false;
};

// "--ao-relative-distance" for "relative_distance" with prefix "ao-".
std::string flag_name(const Spec& spec, std::string_view prefix);
// The command line's text as a value of the spec's kind, or a problem ("an integer expected").
Result<Value> from_text(const Spec& spec, std::string_view text);
// A value as the spec takes it: its kind and range checked, an integer made a number where a
// number is wanted. The problem says what is accepted ("1 to 1048576", "use sobol or random").
Result<Value> accept(const Spec& spec, Value value);
// "integer 1 to 1048576", "sobol, random", "true/false": the docs' type column.
std::string type_text(const Spec& spec);
// A default as help and docs show it: 0.25, 1e-05, sobol; "" for null (unset).
std::string value_text(const nlohmann::json& value);

template <class T>
struct Param {
  Spec spec;
  // Stores an accepted value in the request; a problem it alone can see ("2048x": not a size), or nothing.
  std::function<std::optional<std::string>(T&, const Value&)> set;
  std::function<nlohmann::json(const T&)> get;  // as --json, stamps and the docs' defaults show it
};

template <class T>
struct Group {
  std::vector<Param<T>> params;
  // Rules across parameters, once all are set (ao::check's ranges of one against another).
  std::function<Status(const T&)> check = [](const T&) { return success(); };

  const Param<T>* find(std::string_view name) const {
    for (const Param<T>& p : params) {
      if (p.spec.name == name) return &p;
    }
    return nullptr;
  }
  std::vector<const Spec*> specs() const {
    std::vector<const Spec*> out;
    for (const Param<T>& p : params) out.push_back(&p.spec);
    return out;
  }
};

// Checks the value and stores it: nothing, or the problem (without the parameter's name).
template <class T>
std::optional<std::string> apply(const Param<T>& p, T& target, const Value& value) {
  auto accepted = accept(p.spec, value);
  if (!accepted) return accepted.error().message;
  return p.set(target, *accepted);
}

// Every parameter's value, by name (sorted, so a reordered manifest stamps the same).
template <class T>
nlohmann::json to_json(const Group<T>& group, const T& target) {
  nlohmann::json j = nlohmann::json::object();
  for (const Param<T>& p : group.params) j[p.spec.name] = p.get(target);
  return j;
}

// A group of a request as the rules see it once a door has read it: its parameters, their values
// (as to_json shows them) and the names the door was given (after inheritance: a manifest's top level).
struct GroupState {
  std::vector<const Spec*> specs;
  nlohmann::json values;
  std::set<std::string> given;
  // Of `given`, those a manifest's top level gave for every entry, not the entry itself: a rule on
  // a list's values (green with normal among maps) lets them be where the list lacks the values,
  // as a project-wide default that applies where it can.
  std::set<std::string> inherited;
};

// How a door writes a parameter of group `group`, alone (`value` null) or set to a value:
// "--ao-texture", "--texture-format ktx2"; "scenes.s.ao.texture", "scenes.s.texture_format = \"ktx2\"".
using Spelling = std::function<std::string(std::size_t group, const Spec& spec, const std::string* value)>;

// A rule a request breaks: the parameter at fault (its group and name) and the message.
struct RuleBreak {
  std::size_t group = 0;
  std::string name;
  std::string message;  // "--ao-into and --ao-texture cannot be given together"
};

// Every Spec's needs, needs_value and excludes over a request's groups; the first broken, or none.
// A name is looked up in the parameter's own group first, then in the others in order.
std::optional<RuleBreak> check_rules(const std::vector<GroupState>& groups, const Spelling& spell);

// --- A request's tree: its groups, each over the part of the request it fills -----------------------

// One group of a request, over the request struct `Root`: its parameters (in the manifest either
// among the entry's own keys or in a sub-table, on the command line with a prefix) and how to reach
// the struct they fill. The doors, the rules, the stamps' and --json's options and the docs walk it.
template <class Root>
struct Branch {
  std::string table;        // a manifest sub-table ("ao" for ao = { ... }), or "" for the entry's own keys
  std::string flag_prefix;  // "ao-" where the command line prefixes them (export's --ao-samples)
  std::vector<const Spec*> specs;
  // Checks the value and stores it in the root (reaching an optional part makes it: AO is on).
  std::function<std::optional<std::string>(Root&, const Spec&, const Value&)> apply;
  std::function<nlohmann::json(const Root&)> values;  // to_json of its part (defaults when unmade)
  std::function<bool(const Root&)> made;              // whether its part is in the request
  std::function<Status(const Root&)> check;           // the group's own rules (when made)
};

template <class Root>
using Tree = std::vector<Branch<Root>>;

// A group as a branch of `Root`: `part(root)` gives the struct it fills (called with a Root& or a
// const Root&); `made(root)` whether it is in the request (always, unless an optional part).
template <class Root, class T, class Part>
Branch<Root> branch(const Group<T>& group, std::string table, std::string flag_prefix, Part part,
                    std::function<bool(const Root&)> made = [](const Root&) { return true; }) {
  Branch<Root> b{std::move(table), std::move(flag_prefix), group.specs(), {}, {}, made, {}};
  b.apply = [&group, part](Root& root, const Spec& spec, const Value& value) -> std::optional<std::string> {
    return apply(*group.find(spec.name), part(root), value);
  };
  b.values = [&group, part, made](const Root& root) { return made(root) ? to_json(group, part(root)) : to_json(group, T{}); };
  b.check = [&group, part, made](const Root& root) { return made(root) ? group.check(part(root)) : success(); };
  return b;
}

// An optional part of a request (exporter::Options::ao): made by the first of its parameters given.
template <class Root, class T>
struct OptionalPart {
  std::optional<T> Root::*member;
  T& operator()(Root& r) const { return (r.*member) ? *(r.*member) : (r.*member).emplace(); }
  const T& operator()(const Root& r) const { return *(r.*member); }
};

template <class Root, class T>
Branch<Root> optional_branch(const Group<T>& group, std::string table, std::string flag_prefix,
                             std::optional<T> Root::*member) {
  return branch<Root>(group, std::move(table), std::move(flag_prefix), OptionalPart<Root, T>{member},
                      [member](const Root& r) { return (r.*member).has_value(); });
}

// A tree over a part of a larger request (a manifest scene's exporter::Options within its
// SceneSpec): each branch reached through `part(outer)`.
template <class Outer, class Root, class Part>
Tree<Outer> subtree(const Tree<Root>& tree, Part part) {
  Tree<Outer> out;
  for (const Branch<Root>& b : tree) {
    out.push_back({b.table, b.flag_prefix, b.specs,
                   [b, part](Outer& o, const Spec& spec, const Value& v) { return b.apply(part(o), spec, v); },
                   [b, part](const Outer& o) { return b.values(part(o)); },
                   [b, part](const Outer& o) { return b.made(part(o)); },
                   [b, part](const Outer& o) { return b.check(part(o)); }});
  }
  return out;
}

// Each branch's state for check_rules; `given[i]` the names the door gave branch i.
template <class Root>
std::vector<GroupState> states_of(const Tree<Root>& tree, const Root& root, const std::vector<std::set<std::string>>& given) {
  std::vector<GroupState> states;
  for (std::size_t i = 0; i < tree.size(); ++i) states.push_back({tree[i].specs, tree[i].values(root), given.at(i)});
  return states;
}

// The rules across the tree's parameters, then each made branch's own: errors placed by the door
// (`place` turns a broken rule or a branch's problem into its error).
template <class Root>
Status finish_tree(const Tree<Root>& tree, const Root& root, const std::vector<std::set<std::string>>& given,
                   const Spelling& spell) {
  if (auto broken = check_rules(states_of(tree, root, given), spell)) return Error{"", broken->message, true};
  for (const Branch<Root>& b : tree) {
    if (Status s = b.check(root); !s) return s;
  }
  return success();
}

// The request's options as --json and stamps show them: the entry's own keys flat, a table's
// branches under its name (null when not made), sorted.
template <class Root>
nlohmann::json tree_json(const Tree<Root>& tree, const Root& root) {
  nlohmann::json j = nlohmann::json::object();
  for (const Branch<Root>& b : tree) {
    std::string pointer = "/" + b.table;  // a nested table "bake.ao" within its table: /bake/ao
    std::replace(pointer.begin(), pointer.end(), '.', '/');
    if (b.table.empty()) {
      j.update(b.values(root));
    } else if (!b.made(root)) {
      if (b.table.find('.') == std::string::npos) j[b.table] = nullptr;  // a nested one is in that null
    } else {
      nlohmann::json& part = j[nlohmann::json::json_pointer(pointer)];
      if (!part.is_object()) part = nlohmann::json::object();
      part.update(b.values(root));
    }
  }
  return j;
}

// The parameters `given` by a later door (the command line over a manifest) copied from its
// request into the other: each as its get() shows it, stored by its set().
template <class T>
void copy_given(const Group<T>& group, const T& from, const std::set<std::string>& given, T& into) {
  for (const Param<T>& p : group.params) {
    if (!given.count(p.spec.name)) continue;
    const nlohmann::json shown = p.get(from);
    Value value = std::string();  // null: an unset text
    if (shown.is_boolean()) value = shown.get<bool>();
    else if (shown.is_number_integer()) value = shown.get<std::int64_t>();
    else if (shown.is_number()) value = shown.get<double>();
    else if (shown.is_string()) value = shown.get<std::string>();
    (void)p.set(into, value);  // accepted once already, by the door that gave it
  }
}

// A manifest's spelling of a value: quoted where TOML writes it as a string.
std::string toml_value_text(const Spec& spec, const std::string& value);

// The docs' reference table: flag (with `flag_prefix`), manifest key, type, default, help.
std::string markdown_table(const std::vector<const Spec*>& specs, const nlohmann::json& defaults,
                           std::string_view flag_prefix);
template <class T>
std::string markdown_table(const Group<T>& group, std::string_view flag_prefix) {
  return markdown_table(group.specs(), to_json(group, T{}), flag_prefix);
}

// --- Parameters of the common kinds, over a field: `field(target)` gives a reference to it -----------

template <class T, class Field>
Param<T> flag(Spec spec, Field field) {
  spec.kind = Kind::flag;
  return {std::move(spec), [field](T& t, const Value& v) -> std::optional<std::string> {
            field(t) = std::get<bool>(v);
            return std::nullopt;
          },
          [field](const T& t) { return nlohmann::json(bool(field(t))); }};
}

template <class T, class Field>
Param<T> integer(Spec spec, Field field) {
  spec.kind = Kind::integer;
  return {std::move(spec), [field](T& t, const Value& v) -> std::optional<std::string> {
            using F = std::remove_reference_t<decltype(field(t))>;
            field(t) = static_cast<F>(std::get<std::int64_t>(v));
            return std::nullopt;
          },
          [field](const T& t) { return nlohmann::json(field(t)); }};
}

// A PNG's bits a channel, 8 or 16, into an integer field.
template <class T, class Field>
Param<T> png_bits(Spec spec, Field field) {
  spec.min = 8, spec.max = 16;
  Param<T> p = integer<T>(std::move(spec), field);
  p.set = [store = p.set](T& t, const Value& v) -> std::optional<std::string> {
    if (std::get<std::int64_t>(v) != 8 && std::get<std::int64_t>(v) != 16) return "8 or 16";
    return store(t, v);
  };
  return p;
}

template <class T, class Field>
Param<T> number(Spec spec, Field field) {
  spec.kind = Kind::number;
  return {std::move(spec), [field](T& t, const Value& v) -> std::optional<std::string> {
            field(t) = std::get<double>(v);
            return std::nullopt;
          },
          [field](const T& t) { return nlohmann::json(field(t)); }};
}

// Text stored as given (the request judges it where it is used: an OCIO colour space); with
// spec.choices, one of them. Empty shows as null (unset).
template <class T, class Field>
Param<T> text(Spec spec, Field field) {
  spec.kind = spec.choices.empty() ? Kind::text : Kind::choice;
  return {std::move(spec), [field](T& t, const Value& v) -> std::optional<std::string> {
            field(t) = std::get<std::string>(v);
            return std::nullopt;
          },
          [field](const T& t) -> nlohmann::json {
            if (field(t).empty()) return nullptr;
            return field(t);
          }};
}

// An enum (or an optional one: unset shows as null) named by a module's NameTable.
template <class T, class Field, class E, std::size_t N>
Param<T> choice(Spec spec, Field field, const NameTable<E, N>& names) {
  spec.kind = Kind::choice;
  spec.choices.clear();
  for (const auto& [value, name] : names) spec.choices.emplace_back(name);
  return {std::move(spec), [field, &names](T& t, const Value& v) -> std::optional<std::string> {
            field(t) = *value_in(names, std::get<std::string>(v));
            return std::nullopt;
          },
          [field, &names](const T& t) -> nlohmann::json {
            const auto& value = field(t);
            if constexpr (requires { value.has_value(); }) {
              if (!value) return nullptr;
              return std::string(name_in(names, *value));
            } else {
              return std::string(name_in(names, value));
            }
          }};
}

}  // namespace matbake::params
