// The TOML manifest (docs/build.md) → pipeline::Manifest. Unknown keys are errors, so that a typo
// does not silently fall back to a default.
#include <toml++/toml.h>

#include <algorithm>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include "matbake/join.hpp"
#include "matbake/ao_params.hpp"
#include "matbake/cluster.hpp"
#include "matbake/delivery_params.hpp"
#include "matbake/encoding_params.hpp"
#include "matbake/export_params.hpp"
#include "matbake/material_params.hpp"
#include "matbake/near_names.hpp"
#include "matbake/pipeline_params.hpp"
#include "matbake/validate_params.hpp"
#include "matbake/read_file.hpp"
#include "matbake/pipeline.hpp"
#include "../io/bounded_toml.hpp"
#include "../params/toml_value.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

// Errors about one manifest, placed at a node's line and column.
struct Reader {
  std::string file;

  Error at(const toml::source_region& where, const std::string& message) const {
    return Error{origin(where), message};
  }
  Error at(const toml::node& node, const std::string& message) const { return at(node.source(), message); }
  std::string origin(const toml::source_region& where) const {
    return file + ":" + std::to_string(where.begin.line) + ":" + std::to_string(where.begin.column);
  }

  // Every value's origin in an entry's table, nested tables' values as "outer.inner".
  void record(const toml::table& table, const std::string& prefix, Origins& origins) const {
    for (const auto& [key, value] : table) {
      const std::string name = prefix + std::string(key.str());
      origins.by_key[name] = origin(value.source());
      if (const toml::table* inner = value.as_table()) record(*inner, name + ".", origins);
    }
  }

  // Every key of `table` is one of `keys`; an unknown one is an error suggesting the nearest.
  Status known_keys(const toml::table& table, const std::string& where, const std::vector<std::string>& keys) const {
    for (const auto& [key, value] : table) {
      if (std::find(keys.begin(), keys.end(), key.str()) != keys.end()) continue;
      const std::string near = did_you_mean(key.str(), keys);
      return at(key.source(), "unknown key '" + std::string(key.str()) + "' in " + where +
                                  (near.empty() ? " (known: " + join(keys, ", ") + ")" : near));
    }
    return success();
  }

  template <class T>
  Status get(const toml::table& table, std::string_view key, const std::string& where, T& out) const {
    const toml::node* node = table.get(key);
    if (!node) return success();
    if constexpr (std::is_same_v<T, double>) {
      if (auto v = node->value<double>()) {
        out = *v;
        return success();
      }
      return at(*node, where + "." + std::string(key) + ": a number expected");
    } else {
      // Integers only from integer nodes: toml++ 3.3 converts a float by a cast that is undefined
      // beyond the integer's range (found by fuzzing: samples = 2e52).
      const bool convertible = !std::is_integral_v<T> || std::is_same_v<T, bool> || node->is_integer();
      if (auto v = convertible ? node->value<T>() : std::nullopt) {
        out = *v;
        return success();
      }
      return at(*node, where + "." + std::string(key) + (std::is_same_v<T, bool> ? ": true or false expected"
                                                         : std::is_same_v<T, std::string> ? ": a string expected"
                                                                                          : ": an integer expected"));
    }
  }
};

bool is_file_name_safe(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  }
  return true;
}


// A manifest's spelling of a request's groups' parameters, each group in its table `wheres[g]`
// ("scenes.s.ao"): "scenes.s.ao.texture", "scenes.s.texture_format = \"ktx2\"".
params::Spelling key_spelling(std::vector<std::string> wheres) {
  return [wheres = std::move(wheres)](std::size_t group, const params::Spec& spec, const std::string* value) {
    const std::string key = wheres.at(group) + "." + spec.name;
    return value ? key + " = " + params::toml_value_text(spec, *value) : key;
  };
}

// A branch's table `table` within `t`: "ao", or nested, "bake.ao"; null when absent (or when a part
// of the way is not a table: read_branches says so of that part).
const toml::node* sub_node(const toml::table& t, std::string_view table) {
  const toml::node* node = &t;
  for (std::size_t start = 0; node && start <= table.size();) {
    const std::size_t dot = std::min(table.find('.', start), table.size());
    const toml::table* in = node->as_table();
    node = in ? in->get(table.substr(start, dot - start)) : nullptr;
    start = dot + 1;
  }
  return node;
}
const toml::table* sub_table(const toml::table& t, std::string_view table) {
  const toml::node* node = sub_node(t, table);
  return node ? node->as_table() : nullptr;
}

// The keys parameters are read from, with their older names.
std::vector<std::string> keys_of(const std::vector<const params::Spec*>& specs) {
  std::vector<std::string> keys;
  for (const params::Spec* spec : specs) {
    keys.push_back(spec->name);
    keys.insert(keys.end(), spec->aliases.begin(), spec->aliases.end());
  }
  return keys;
}

// The manifest keys of a request tree's entry besides `keys`: its plain branches' keys (with older
// names) and the names of its tables.
template <class Root>
std::vector<std::string> keys_of_tree(const params::Tree<Root>& tree, std::vector<std::string> keys) {
  for (const params::Branch<Root>& b : tree) {
    const std::string table = b.table.substr(0, b.table.find('.'));  // "bake" of "bake.ao"
    for (const std::string& key : b.table.empty() ? keys_of(b.specs) : std::vector<std::string>{table}) {
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
    }
  }
  return keys;
}

// The keys of a tree's table `table` ("validate"): every branch's in it.
template <class Root>
std::vector<std::string> keys_in_table(const params::Tree<Root>& tree, const std::string& table) {
  std::vector<std::string> keys;
  for (const params::Branch<Root>& b : tree) {
    if (b.table.rfind(table + ".", 0) == 0) {  // a table within it: "ao" of "bake.ao" in "bake"
      const std::string inner = b.table.substr(table.size() + 1, b.table.find('.', table.size() + 1) - table.size() - 1);
      if (std::find(keys.begin(), keys.end(), inner) == keys.end()) keys.push_back(inner);
    }
    if (b.table != table) continue;
    const std::vector<std::string> own = keys_of(b.specs);
    keys.insert(keys.end(), own.begin(), own.end());
  }
  return keys;
}

// The manifest's top level as errors name it: its own keys "manifest.png_compression", its tables'
// "validate.tolerance".
const std::string kTopLevel = "manifest";

// How errors name a branch's table within an entry `where` ("scenes.s" → "scenes.s.ao").
template <class Root>
std::string where_of(const params::Branch<Root>& b, const std::string& where) {
  if (b.table.empty()) return where;
  return where == kTopLevel ? b.table : where + "." + b.table;
}

// Each branch's names a manifest gave: the top level's, then the entry's own.
using Given = std::vector<std::set<std::string>>;

// A request as a manifest entry (or the top level every entry starts from) gives it.
template <class Root>
struct Entry {
  Root request;
  Given given;
};

// One key `name` of branch `b` (of index `i`), read into the entry: an older name with a note.
template <class Root>
Status read_key(const Reader& r, const params::Branch<Root>& b, const std::string& at, const params::Spec& spec,
                const toml::key& key, const toml::node& value, Entry<Root>& entry, std::size_t i, std::vector<std::string>& notes) {
  const std::string name(key.str());
  if (name != spec.name) {
    notes.push_back(r.origin(key.source()) + ": " + at + "." + name + " is now called " + spec.name + " (the old name still works)");
  }
  auto v = params::toml_value(value);
  std::optional<std::string> problem = v ? b.apply(entry.request, spec, *v) : v.error().message;
  if (problem) return r.at(value, at + "." + name + ": " + *problem);
  entry.given[i].insert(spec.name);
  return success();
}

// The keys of `t` (`where`: "scenes.s") a tree describes, stored in `entry`: plain branches' among
// the table's own keys, table branches' in their sub-table (which holds those only); an older key is
// read with a note. The rules are check_tree's, once the entry is complete.
template <class Root>
Status read_branches(const Reader& r, const toml::table& t, const std::string& where, const params::Tree<Root>& tree,
                     Entry<Root>& entry, std::vector<std::string>& notes) {
  entry.given.resize(tree.size());
  for (std::size_t i = 0; i < tree.size(); ++i) {
    const params::Branch<Root>& b = tree[i];
    const std::string at = where_of(b, where);
    const toml::node* node = b.table.empty() ? &static_cast<const toml::node&>(t) : sub_node(t, b.table);
    if (!node) continue;
    const toml::table* table = node->as_table();
    if (!table) return r.at(*node, at + " must be a table: " + b.table + " = { ... }");
    if (!b.table.empty()) {
      if (Status s = r.known_keys(*table, at, keys_in_table(tree, b.table)); !s) return s;
    }
    // In the group's order, not the table's: a delivery profile is set before the keys beside it.
    for (const params::Spec* spec : b.specs) {
      std::vector<std::string> names = spec->aliases;
      names.insert(names.begin(), spec->name);
      for (const std::string& name : names) {
        const auto found = table->find(name);
        if (found == table->end()) continue;
        if (Status s = read_key(r, b, at, *spec, found->first, found->second, entry, i, notes); !s) return s;
      }
    }
  }
  return success();
}


// Where a branch's key is written: in the entry `t`, else in the top level `top` it came from, else
// the entry's table of the branch.
template <class Root>
const toml::node& key_node(const params::Branch<Root>& b, const std::string& key, const toml::table& t,
                           const toml::table& top) {
  for (const toml::table* in : {&t, &top}) {
    const toml::table* table = b.table.empty() ? in : sub_table(*in, b.table);
    if (const toml::node* found = table ? table->get(key) : nullptr) return *found;
  }
  const toml::table* own = b.table.empty() ? &t : sub_table(t, b.table);
  return own ? *own : t;
}

// The rules across a complete entry's tree, in the manifest's spelling at the key at fault; then
// each branch's own.
template <class Root>
Status check_tree(const Reader& r, const toml::table& t, const toml::table& top, const std::string& where,
                  const params::Tree<Root>& tree, const Entry<Root>& entry) {
  std::vector<std::string> wheres;
  for (const params::Branch<Root>& b : tree) wheres.push_back(where_of(b, where));
  std::vector<params::GroupState> states = params::states_of(tree, entry.request, entry.given);
  for (std::size_t i = 0; i < tree.size(); ++i) {
    const toml::table* own = tree[i].table.empty() ? &t : sub_table(t, tree[i].table);
    for (const params::Spec* spec : tree[i].specs) {
      const bool in_entry = own && (own->contains(spec->name) ||
                                    std::ranges::any_of(spec->aliases, [&](const std::string& a) { return own->contains(a); }));
      if (entry.given[i].count(spec->name) && !in_entry) states[i].inherited.insert(spec->name);
    }
  }
  if (auto broken = params::check_rules(states, key_spelling(wheres))) {
    return r.at(key_node(tree[broken->group], broken->name, t, top), broken->message);
  }
  for (std::size_t i = 0; i < tree.size(); ++i) {
    if (Status s = tree[i].check(entry.request); !s) {
      const toml::table* own = tree[i].table.empty() ? &t : sub_table(t, tree[i].table);
      return r.at(own ? *own : t, wheres[i] + ": " + s.error().message);
    }
  }
  return success();
}

// An entry's request over `entry` (the top level's, which its keys override): read, then checked.
template <class Root>
Status read_entry(const Reader& r, const toml::table& t, const toml::table& top, const std::string& where,
                  const params::Tree<Root>& tree, Entry<Root>& entry, std::vector<std::string>& notes) {
  if (Status s = read_branches(r, t, where, tree, entry, notes); !s) return s;
  return check_tree(r, t, top, where, tree, entry);
}

// layout = "gltf-orm" (a preset) or "layouts/mine" / "layouts/mine.json" (a file beside the manifest).
Result<std::optional<LayoutChoice>> read_layout(const Reader& r, const toml::table& t, std::string_view key,
                                                const std::string& where, const fs::path& folder) {
  const toml::node* node = t.get(key);
  if (!node) return std::optional<LayoutChoice>();
  auto text = node->value<std::string>();
  if (!text) return r.at(*node, where + "." + std::string(key) + ": a preset's name or a layout file expected");
  if (text->empty()) return std::optional<LayoutChoice>();
  auto resolved = pack::resolve_layout(*text, folder);
  if (!resolved) return r.at(*node, where + "." + std::string(key) + ": " + resolved.error().to_string());
  return std::optional<LayoutChoice>(LayoutChoice{*text, std::move(resolved->layout), std::move(resolved->file)});
}

// sources = { kd = "t/paint.png", ks = 0.04, gloss = "0.6" }: files or constants.
// A source's table form: a file and which of its channels.
Result<pack::SourceInput> read_file_source(const Reader& r, const toml::table& t, const std::string& where,
                                           const Manifest& m) {
  if (Status s = r.known_keys(t, where, {"file", "channel"}); !s) return s.error();
  std::string file, channel;
  for (Status s : {r.get(t, "file", where, file), r.get(t, "channel", where, channel)}) {
    if (!s) return s.error();
  }
  if (file.empty()) return r.at(t, where + ": needs file = \"...\"");
  pack::SourceInput in;
  in.file = m.folder / file;
  if (const toml::node* c = t.get("channel")) {
    const auto picked = value_in(pack::kFileChannelNames, channel);
    if (!picked) return r.at(*c, where + ".channel: '" + channel + "' is not " + names_in(pack::kFileChannelNames));
    in.channels = *picked;
  }
  return in;
}

Status read_sources(const Reader& r, const toml::node& sources, const std::string& where, const Manifest& m,
                    MaterialSpec& spec) {
  if (!sources.is_table()) return r.at(sources, where + ".sources must be a table");
  for (const auto& [key, value] : *sources.as_table()) {
    const std::string source(key.str());
    if (!material::find_source(source)) {
      std::vector<std::string> known;
      for (const material::Source& s : material::sources()) known.emplace_back(s.name);
      const std::string near = did_you_mean(source, known);
      return r.at(key.source(), where + ".sources: unknown source '" + source + "'" +
                                    (near.empty() ? " (known: " + join(known, ", ") + ")" : near));
    }
    pack::SourceInput in{source, {}, {}};
    if (const toml::table* file = value.as_table()) {  // { file = "sg.png", channel = "a" }
      auto read = read_file_source(r, *file, where + ".sources." + source, m);
      if (!read) return read.error();
      in.file = read->file;
      in.channels = read->channels;
    } else if (auto text = value.value<std::string>()) {  // a file, or numbers written as text (as on the command line)
      auto parsed = pack::source_from_text(source, *text, m.folder);
      if (!parsed) return r.at(value, where + ".sources." + source + ": " + parsed.error().message);
      in = std::move(*parsed);
    } else if (auto number = value.value<double>()) {
      if (!material::is_valid_constant(*number)) return r.at(value, where + ".sources." + source + ": values are in [0, 1]");
      in.constant = {*number};
    } else if (const toml::array* list = value.as_array()) {
      for (const toml::node& n : *list) {
        auto x = n.value<double>();
        if (!x) return r.at(n, where + ".sources." + source + ": numbers expected");
        if (!material::is_valid_constant(*x)) return r.at(n, where + ".sources." + source + ": values are in [0, 1]");
        in.constant.push_back(*x);
      }
    } else {
      return r.at(value, where + ".sources." + source +
                             ": a file name, a number, a list of 3 numbers or { file = ..., channel = ... } expected");
    }
    // A material rule's override replaces the rule's source of that name.
    std::erase_if(spec.sources, [&](const pack::SourceInput& s) { return s.name == source; });
    spec.sources.push_back(std::move(in));
  }
  if (spec.sources.empty()) return r.at(sources, where + ".sources is empty");
  return success();
}

// packed = { layout = "schuler", files = ["t/a.png", "t/b.png"] }: a layout's textures.
Status read_packed_entry(const Reader& r, const toml::node& packed, const std::string& where, const Manifest& m,
                         MaterialSpec& spec) {
  const toml::table* p = packed.as_table();
  if (!p) return r.at(packed, where + ".packed must be a table");
  if (Status s = r.known_keys(*p, where + ".packed", {"layout", "files"}); !s) return s.error();
  auto packed_layout = read_layout(r, *p, "layout", where + ".packed", m.folder);
  if (!packed_layout) return packed_layout.error();
  spec.packed = std::move(*packed_layout);
  const toml::array* files = p->get_as<toml::array>("files");
  if (!spec.packed || !files || files->empty()) {
    return r.at(packed, where + ".packed needs layout = \"...\" and files = [\"...\", ...]");
  }
  for (const toml::node& f : *files) {
    auto file = f.value<std::string>();
    if (!file) return r.at(f, where + ".packed.files: file names expected");
    spec.packed_files.push_back(m.folder / *file);
  }
  return success();
}

// A material entry over `defaults` (the manifest's top level, or for a rule's override the rule's
// material); `structure` are further keys the entry may hold (a rule's `match` and `overrides`).
// `bits` the format of the material's textures cannot store (half into PNG), wherever either was
// set (the material, a rule, the defaults): an error at the key this table gives.
Status check_bits_and_format(const Reader& r, const toml::table& t, const std::string& where,
                             const pack::MaterialOptions& options) {
  if (!options.bits) return success();
  auto problem = image::sample_type_problem("texture." + options.format, *options.bits);
  if (!problem) return success();
  const toml::node* at = t.get("bits") ? t.get("bits") : t.get("format");
  return r.at(at ? *at : static_cast<const toml::node&>(t),
              where + ": bits = \"" + std::string(image::sample_type_name(*options.bits)) + "\" with format = \"" +
                  options.format + "\": " + *problem);
}

// The manifest's top level: every entry starts from its values of the entry's parameters (one rule:
// any key of a material's or a scene's request tree, tables included), then says otherwise.
struct TopLevel {
  const toml::table& table;
  Entry<MaterialSpec> material;
  Entry<SceneSpec> scene;
};

Result<Entry<MaterialSpec>> read_material(const Reader& r, const std::string& name, const std::string& where,
                                          const toml::node& node, const Manifest& m, const toml::table& top,
                                          const Entry<MaterialSpec>& defaults, std::vector<std::string>& notes,
                                          std::vector<std::string> structure = {}) {
  const toml::table* t = node.as_table();
  if (!t) return r.at(node, where + " must be a table");
  if (!is_file_name_safe(name)) {
    return r.at(node, "material name '" + name + "': letters, digits, '_', '-' and '.' only (it names files)");
  }
  structure.insert(structure.end(), {"sources", "packed", "layout", "reference"});
  if (Status s = r.known_keys(*t, where, keys_of_tree(material_tree(), structure)); !s) return s.error();
  Entry<MaterialSpec> entry = defaults;
  MaterialSpec& spec = entry.request;
  spec.name = name;
  spec.origins.by_key[""] = r.origin(node.source());
  r.record(*t, "", spec.origins);
  for (Status s : {read_entry(r, *t, top, where, material_tree(), entry, notes), r.get(*t, "reference", where, spec.reference)}) {
    if (!s) return s.error();
  }
  if (Status s = check_bits_and_format(r, *t, where, spec.options); !s) return s.error();
  auto layout = read_layout(r, *t, "layout", where, m.folder);
  if (!layout) return layout.error();
  if (*layout) spec.layout = std::move(*layout);  // else the defaults' (a rule's, for its overrides)

  const toml::node* sources = t->get("sources");
  const toml::node* packed = t->get("packed");
  if (!sources && !packed && spec.sources.empty() && !spec.packed) {
    return r.at(node, where + ": give sources = {...}, packed = {...} or both (the sources replace packed maps)");
  }
  if (Status s = sources ? read_sources(r, *sources, where, m, spec) : success(); !s) return s.error();
  if (Status s = packed ? read_packed_entry(r, *packed, where, m, spec) : success(); !s) return s.error();
  return entry;
}

// "{name}" in `text` replaced by `name`.
std::string with_name(std::string text, const std::string& name) {
  for (std::size_t at = text.find("{name}"); at != std::string::npos; at = text.find("{name}", at + name.size())) {
    text.replace(at, 6, name);
  }
  return text;
}

// The names a rule's `match` finds: files of its folder named prefix{name}suffix, sorted.
Result<std::vector<std::string>> rule_matches(const Reader& r, const toml::node& match, const std::string& where,
                                              const Manifest& m, std::vector<std::string>& notes) {
  const auto text = match.value<std::string>();
  const fs::path pattern = text ? m.folder / *text : fs::path();
  const std::string file = pattern.filename().string();
  const std::size_t at = file.find("{name}");
  if (!text || at == std::string::npos || file.find("{name}", at + 1) != std::string::npos ||
      pattern.parent_path().string().find("{name}") != std::string::npos) {
    return r.at(match, where + ".match: a file pattern with {name} once, in the file name (\"textures/{name}_BaseColor.png\")");
  }
  const std::string prefix = file.substr(0, at), suffix = file.substr(at + 6);
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(pattern.parent_path(), ec)) {
    const std::string f = entry.path().filename().string();
    if (f.size() <= prefix.size() + suffix.size() || !f.starts_with(prefix) || !f.ends_with(suffix) || !entry.is_regular_file(ec)) continue;
    const std::string name = f.substr(prefix.size(), f.size() - prefix.size() - suffix.size());
    if (is_file_name_safe(name)) {
      names.push_back(name);
    } else {
      notes.push_back(r.origin(match.source()) + ": " + where + ": " + entry.path().string() + " skipped: '" + name +
                      "' is not a material name (letters, digits, '_', '-', '.')");
    }
  }
  if (ec) return r.at(match, where + ".match: " + pattern.parent_path().string() + ": " + ec.message());
  std::sort(names.begin(), names.end());
  // A typo would otherwise drop every material the rule made, and the cleaner their outputs.
  if (names.empty()) return r.at(match, where + ".match: '" + *text + "' matches no file in " + pattern.parent_path().string());
  return names;
}

// [material_rules.NAME]: a material per file `match` finds, its keys those of a material with
// "{name}" in its file names, and `overrides.NAME` tables of material keys for some of them.
Status read_material_rule(const Reader& r, const std::string& rule, const toml::node& node, Manifest& m,
                          const TopLevel& top) {
  const std::string where = "material_rules." + rule;
  const toml::table* t = node.as_table();
  if (!t) return r.at(node, where + " must be a table");
  const toml::node* match = t->get("match");
  if (!match) return r.at(node, where + ": needs match = \"textures/{name}_BaseColor.png\" (a file per material)");
  auto names = rule_matches(r, *match, where, m, m.notes);
  if (!names) return names.error();
  auto shared = read_material(r, rule, where, node, m, top.table, top.material, m.notes, {"match", "overrides"});
  if (!shared) return shared.error();
  const toml::table* overrides = nullptr;
  if (const toml::node* o = t->get("overrides")) {
    overrides = o->as_table();
    if (!overrides) return r.at(*o, where + ".overrides must be a table of tables: [" + where + ".overrides.NAME]");
    for (const auto& [key, value] : *overrides) {
      if (!std::binary_search(names->begin(), names->end(), std::string(key.str()))) {
        const std::string near = did_you_mean(std::string(key.str()), *names);
        return r.at(key.source(), where + ".overrides." + std::string(key.str()) + ": no such match" +
                                      (near.empty() ? " (its matches now: " + join(*names, ", ") + ")" : near));
      }
    }
  }
  MaterialRule expanded{rule, r.origin(node.source()), {}, (m.folder / *match->value<std::string>()).parent_path()};
  for (const std::string& name : *names) {
    Entry<MaterialSpec> entry = *shared;
    MaterialSpec& spec = entry.request;
    spec.name = name;
    for (pack::SourceInput& s : spec.sources) s.file = with_name(s.file.string(), name);
    for (fs::path& f : spec.packed_files) f = with_name(f.string(), name);
    spec.reference = with_name(spec.reference, name);
    if (const toml::node* own = overrides ? overrides->get(name) : nullptr) {
      auto overridden = read_material(r, name, where + ".overrides." + name, *own, m, top.table, entry, m.notes);
      if (!overridden) return overridden.error();
      entry = std::move(*overridden);
    }
    for (const MaterialSpec& other : m.materials) {
      if (other.name == name) {
        return r.at(*match, where + ": '" + name + "' is also a material at " + other.origins.of("") + "; rename one");
      }
    }
    m.materials.push_back(std::move(spec));
    expanded.materials.push_back(name);
  }
  m.rules.push_back(std::move(expanded));
  return success();
}

// A scene bakes when its own table has `bake` (the top level's gives defaults only), from a
// high-poly it names; its ao map is the occlusion, so the export's own AO would bake another.
Status read_scene_bake(const Reader& r, const toml::table& t, const std::string& where, const Manifest& m, SceneSpec& spec) {
  const toml::node* node = t.get("bake");
  if (!node) {
    spec.bake.reset();
    return success();
  }
  if (!spec.bake || spec.bake->from.empty()) return r.at(*node, where + ".bake: from = \"high.glb\" is required");
  spec.bake->high = m.folder / spec.bake->from;
  spec.bake->cage = spec.bake->cage_file.empty() ? fs::path() : m.folder / spec.bake->cage_file;
  for (const auto* maps : {&spec.bake->request.bake.maps, &spec.bake->request.bake.vertex_maps}) {
    if (!spec.options.ao || std::find(maps->begin(), maps->end(), bake::Map::ao) == maps->end()) continue;
    const char* key = maps == &spec.bake->request.bake.maps ? "maps" : "vertex_maps";
    const toml::node* ao = t.get("ao");
    return r.at(ao ? *ao : *node, where + ": the export's ao and the bake's ao map would both make the occlusion; "
                                  "keep one (drop `ao`, or ao from bake." + key + ")");
  }
  return success();
}

Result<SceneSpec> read_scene(const Reader& r, const std::string& name, const toml::node& node, const Manifest& m,
                             const TopLevel& top, std::vector<std::string>& notes) {
  const std::string where = "scenes." + name;
  const toml::table* t = node.as_table();
  if (!t) return r.at(node, where + " must be a table");
  if (!is_file_name_safe(name)) return r.at(node, "scene name '" + name + "': letters, digits, '_', '-' and '.' only");
  if (Status s = r.known_keys(*t, where, keys_of_tree(scene_tree(), {"input", "output", "materials"})); !s) return s.error();
  Entry<SceneSpec> entry = top.scene;
  SceneSpec& spec = entry.request;
  spec.name = name;
  spec.origins.by_key[""] = r.origin(node.source());
  r.record(*t, "", spec.origins);
  std::string input, output = name + ".glb";
  for (Status s : {r.get(*t, "input", where, input), r.get(*t, "output", where, output),
                   read_entry(r, *t, top.table, where, scene_tree(), entry, notes)}) {
    if (!s) return s.error();
  }
  if (input.empty()) return r.at(node, where + ": input = \"scene.gltf\" is required");
  spec.input = m.folder / input;
  const fs::path out(output);
  const fs::path ext = out.extension();
  if (out.is_absolute() || out.lexically_normal().string().rfind("..", 0) == 0 || (ext != ".gltf" && ext != ".glb")) {
    return r.at(t->get("output") ? *t->get("output") : node,
                where + ".output '" + output + "': a .gltf or .glb path inside the output folder");
  }
  spec.output = out.lexically_normal();
  if (Status s = read_scene_bake(r, *t, where, m, spec); !s) return s.error();
  if (const toml::node* mats = t->get("materials")) {
    if (!mats->is_table()) return r.at(*mats, where + ".materials must be a table: { \"glTF name\" = \"material\" }");
    for (const auto& [key, value] : *mats->as_table()) {
      auto target = value.value<std::string>();
      if (!target) return r.at(value, where + ".materials: a manifest material's name expected");
      spec.materials[std::string(key.str())] = *target;
    }
  }
  return std::move(entry.request);
}

}  // namespace

const std::string& Origins::of(const std::string& key) const {
  static const std::string none;
  if (const auto found = by_key.find(key); found != by_key.end()) return found->second;
  const auto entry = by_key.find("");
  return entry != by_key.end() ? entry->second : none;
}

Result<Manifest> parse_manifest(std::string_view toml_text, const fs::path& file) {
  return guarded(file.string(), [&]() -> Result<Manifest> {
    Manifest m;
    std::error_code ec;
    m.file = fs::absolute(file, ec).lexically_normal();
    m.folder = m.file.parent_path();
    const Reader r{file.string()};
    toml::table doc;
    const TomlDepth depth = toml_key_depth(toml_text);
    if (std::string problem = toml_depth_problem(depth); !problem.empty()) return Error{file.string() + ":" + std::to_string(depth.line), problem};
    try {
      doc = toml::parse(toml_text, file.string());
    } catch (const toml::parse_error& e) {
      return Error{file.string() + ":" + std::to_string(e.source().begin.line) + ":" +
                       std::to_string(e.source().begin.column),
                   "not valid TOML: " + std::string(e.description())};
    }
    const std::vector<std::string> own_keys{"output", "table", "materials", "material_rules", "scenes", "cluster",
                                            "shared_output", "prune", "max_pixels", "report"};
    if (Status s = r.known_keys(doc, "the manifest", keys_of_tree(material_tree(), keys_of_tree(scene_tree(), own_keys))); !s) {
      return s.error();
    }
    m.origins.by_key[""] = file.string();
    for (const auto& [key, value] : doc) {
      if (!value.is_table()) m.origins.by_key[std::string(key.str())] = r.origin(value.source());
    }
    std::string output = "out", table;
    if (Status s = r.get(doc, "output", "manifest", output); !s) return s.error();
    if (Status s = r.get(doc, "table", "manifest", table); !s) return s.error();
    if (Status s = r.get(doc, "shared_output", "manifest", m.shared_output); !s) return s.error();
    if (Status s = r.get(doc, "prune", "manifest", m.prune); !s) return s.error();
    if (Status s = r.get(doc, "report", "manifest", m.report); !s) return s.error();
    if (Status s = r.get(doc, "max_pixels", "manifest", m.max_pixels); !s) return s.error();
    if (m.max_pixels < 0 || (doc.get("max_pixels") && m.max_pixels == 0)) {
      return r.at(*doc.get("max_pixels"), "manifest.max_pixels: a count of pixels, 1 or more");
    }
    m.output = (m.folder / output).lexically_normal();
    if (!table.empty()) m.table = m.folder / table;
    TopLevel top{doc, {}, {}};
    std::vector<std::string> top_notes;  // a key both trees read is noted once
    for (Status s : {read_branches(r, doc, kTopLevel, material_tree(), top.material, top_notes),
                     read_branches(r, doc, kTopLevel, scene_tree(), top.scene, top_notes)}) {
      if (!s) return s.error();
    }
    for (std::string& note : top_notes) {
      if (std::find(m.notes.begin(), m.notes.end(), note) == m.notes.end()) m.notes.push_back(std::move(note));
    }
    if (const toml::node* c = doc.get("cluster")) {
      if (!c->is_table()) return r.at(*c, "cluster must be a table: [cluster]");
      static const params::Tree<ClusterOptions> cluster{
          params::branch<ClusterOptions>(cluster_params(), "", "", [](auto& o) -> auto& { return o; })};
      Entry<ClusterOptions> read{m.cluster, {}};
      for (Status s : {r.known_keys(*c->as_table(), "cluster", keys_of_tree(cluster, {})),
                       read_entry(r, *c->as_table(), *c->as_table(), "cluster", cluster, read, m.notes)}) {
        if (!s) return s.error();
      }
      m.cluster = std::move(read.request);
    }
    if (const toml::node* mats = doc.get("materials")) {
      if (!mats->is_table()) return r.at(*mats, "materials must be a table of tables: [materials.NAME]");
      for (const auto& [key, value] : *mats->as_table()) {
        auto entry = read_material(r, std::string(key.str()), "materials." + std::string(key.str()), value, m, doc,
                                   top.material, m.notes);
        if (!entry) return entry.error();
        m.materials.push_back(std::move(entry->request));
      }
    }
    if (const toml::node* rules = doc.get("material_rules")) {
      if (!rules->is_table()) return r.at(*rules, "material_rules must be a table of tables: [material_rules.NAME]");
      for (const auto& [key, value] : *rules->as_table()) {
        if (Status s = read_material_rule(r, std::string(key.str()), value, m, top); !s) return s.error();
      }
    }
    if (const toml::node* scenes = doc.get("scenes")) {
      if (!scenes->is_table()) return r.at(*scenes, "scenes must be a table of tables: [scenes.NAME]");
      for (const auto& [key, value] : *scenes->as_table()) {
        auto spec = read_scene(r, std::string(key.str()), value, m, top, m.notes);
        if (!spec) return spec.error();
        m.scenes.push_back(std::move(*spec));
      }
    }
    if (m.materials.empty() && m.scenes.empty()) return Error{file.string(), "no [materials.NAME] or [scenes.NAME]: nothing to build"};
    std::set<std::string> names;
    for (const MaterialSpec& s : m.materials) names.insert(s.name);
    for (const SceneSpec& s : m.scenes) {
      for (const auto& [gltf_name, material] : s.materials) {
        if (!names.count(material)) {
          std::vector<std::string> known(names.begin(), names.end());
          return Error{s.origins.of("materials." + gltf_name), "scenes." + s.name + ".materials: '" + gltf_name + "' = '" +
                                                                    material + "', but there is no [materials." + material +
                                                                    "]" + did_you_mean(material, known)};
        }
      }
    }
    return m;
  });
}

Result<Manifest> read_manifest(const fs::path& file) {
  std::string text;
  if (!read_whole_file(file, text)) return Error{file.string(), "cannot read the manifest (missing, unreadable or not a file)"};
  return parse_manifest(text, file);
}

}  // namespace matbake::pipeline
