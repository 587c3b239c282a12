// The TOML manifest (docs/build.md) → build::Manifest. Unknown keys are errors, so that a typo
// does not silently fall back to a default.
#include <toml++/toml.h>

#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include "matbake/build.hpp"

namespace matbake::build {
namespace fs = std::filesystem;
namespace {

// Errors about one manifest, placed at a node's line and column.
struct Reader {
  std::string file;

  Error at(const toml::source_region& where, const std::string& message) const {
    return Error{file + ":" + std::to_string(where.begin.line) + ":" + std::to_string(where.begin.column), message};
  }
  Error at(const toml::node& node, const std::string& message) const { return at(node.source(), message); }

  Status known_keys(const toml::table& table, const std::string& where, std::initializer_list<std::string_view> keys) const {
    for (const auto& [key, value] : table) {
      bool known = false;
      for (std::string_view k : keys) known = known || key.str() == k;
      if (!known) {
        std::string list;
        for (std::string_view k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
        return at(key.source(), "unknown key '" + std::string(key.str()) + "' in " + where + " (known: " + list + ")");
      }
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
      if (auto v = node->value<T>()) {
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

Status read_validation(const Reader& r, const toml::table& t, const std::string& where, ValidationRules& rules) {
  if (Status s = r.known_keys(t, where, {"enabled", "tolerance", "max_violations", "heatmap"}); !s) return s;
  for (Status s : {r.get(t, "enabled", where, rules.enabled), r.get(t, "tolerance", where, rules.tolerance),
                   r.get(t, "max_violations", where, rules.max_violations), r.get(t, "heatmap", where, rules.heatmap)}) {
    if (!s) return s;
  }
  if (!(rules.tolerance > 0) || !(rules.max_violations >= 0 && rules.max_violations <= 1)) {
    return r.at(t, where + ": tolerance must be > 0 and max_violations in [0, 1]");
  }
  return success();
}

template <class T>
Status read_transfer(const Reader& r, const toml::table& t, const std::string& where, T& transfer,
                     std::string_view key = "transfer") {
  std::string name;
  if (Status s = r.get(t, key, where, name); !s || name.empty()) return s;
  auto parsed = color::transfer_from_name(name);
  if (!parsed) {
    return r.at(*t.get(key), where + "." + std::string(key) + " '" + name + "': use srgb, gamma2.2 or linear");
  }
  transfer = *parsed;
  return success();
}

Result<MaterialSpec> read_material(const Reader& r, const std::string& name, const toml::node& node,
                                   const Manifest& m, color::Transfer transfer, const ValidationRules& rules) {
  const std::string where = "materials." + name;
  const toml::table* t = node.as_table();
  if (!t) return r.at(node, where + " must be a table");
  if (!is_file_name_safe(name)) {
    return r.at(node, "material name '" + name + "': letters, digits, '_', '-' and '.' only (it names files)");
  }
  if (Status s = r.known_keys(*t, where, {"sources", "packed", "transfer", "decode", "resize", "layout", "format", "bits",
                                          "mapping", "reference", "validate"});
      !s) {
    return s.error();
  }
  MaterialSpec spec;
  spec.name = name;
  spec.transfer = transfer;
  spec.validation = rules;
  if (Status s = read_transfer(r, *t, where, spec.transfer); !s) return s.error();
  if (Status s = read_transfer(r, *t, where, spec.decode, "decode"); !s) return s.error();
  std::string bits, mapping;
  for (Status s : {r.get(*t, "resize", where, spec.resize), r.get(*t, "layout", where, spec.layout),
                   r.get(*t, "format", where, spec.format), r.get(*t, "bits", where, bits),
                   r.get(*t, "mapping", where, mapping), r.get(*t, "reference", where, spec.reference)}) {
    if (!s) return s.error();
  }
  if (spec.format != "png" && spec.format != "exr" && spec.format != "tif") {
    return r.at(*t->get("format"), where + ".format '" + spec.format + "': use png, exr or tif");
  }
  if (spec.format == "exr") spec.bits = image::SampleType::half;
  if (!bits.empty()) {
    auto type = image::sample_type_from_name(bits);
    if (!type) return r.at(*t->get("bits"), where + ".bits '" + bits + "': use 8, 16, half or float");
    spec.bits = *type;
  }
  if (!mapping.empty() && !workflow::roughness_mapping_from_name(mapping, spec.mapping)) {
    return r.at(*t->get("mapping"), where + ".mapping '" + mapping + "': unknown");
  }
  if (const toml::node* v = t->get("validate")) {
    if (!v->is_table()) return r.at(*v, where + ".validate must be a table");
    if (Status s = read_validation(r, *v->as_table(), where + ".validate", spec.validation); !s) return s.error();
  }

  const toml::node* sources = t->get("sources");
  const toml::node* packed = t->get("packed");
  if (bool(sources) == bool(packed)) return r.at(node, where + ": give either sources = {...} or packed = {...}");
  if (sources) {
    if (!sources->is_table()) return r.at(*sources, where + ".sources must be a table");
    for (const auto& [key, value] : *sources->as_table()) {
      const std::string source(key.str());
      if (!pack::find_source(source)) {
        std::string known;
        for (const pack::Source& s : pack::sources()) known += (known.empty() ? "" : ", ") + std::string(s.name);
        return r.at(key.source(), where + ".sources: unknown source '" + source + "' (known: " + known + ")");
      }
      pack::SourceInput in{source, {}, {}};
      if (auto file = value.value<std::string>()) {
        in.file = m.folder / *file;
      } else if (auto number = value.value<double>()) {
        in.constant = {*number};
      } else if (const toml::array* list = value.as_array()) {
        for (const toml::node& n : *list) {
          auto x = n.value<double>();
          if (!x) return r.at(n, where + ".sources." + source + ": numbers expected");
          in.constant.push_back(*x);
        }
      } else {
        return r.at(value, where + ".sources." + source + ": a file name, a number or a list of 3 numbers expected");
      }
      spec.sources.push_back(std::move(in));
    }
    if (spec.sources.empty()) return r.at(*sources, where + ".sources is empty");
  } else {
    const toml::table* p = packed->as_table();
    if (!p) return r.at(*packed, where + ".packed must be a table");
    if (Status s = r.known_keys(*p, where + ".packed", {"layout", "files"}); !s) return s.error();
    if (Status s = r.get(*p, "layout", where + ".packed", spec.packed_layout); !s) return s.error();
    const toml::array* files = p->get_as<toml::array>("files");
    if (spec.packed_layout.empty() || !files || files->empty()) {
      return r.at(*packed, where + ".packed needs layout = \"...\" and files = [\"...\", ...]");
    }
    for (const toml::node& f : *files) {
      auto file = f.value<std::string>();
      if (!file) return r.at(f, where + ".packed.files: file names expected");
      spec.packed_files.push_back(m.folder / *file);
    }
  }
  return spec;
}

Result<SceneSpec> read_scene(const Reader& r, const std::string& name, const toml::node& node, const Manifest& m) {
  const std::string where = "scenes." + name;
  const toml::table* t = node.as_table();
  if (!t) return r.at(node, where + " must be a table");
  if (!is_file_name_safe(name)) return r.at(node, "scene name '" + name + "': letters, digits, '_', '-' and '.' only");
  if (Status s = r.known_keys(*t, where, {"input", "output", "materials", "match_names", "ao", "dielectric_f0", "orm"});
      !s) {
    return s.error();
  }
  SceneSpec spec;
  spec.name = name;
  std::string input, output = name + ".glb", dielectric = "specular";
  for (Status s : {r.get(*t, "input", where, input), r.get(*t, "output", where, output),
                   r.get(*t, "match_names", where, spec.match_names), r.get(*t, "dielectric_f0", where, dielectric),
                   r.get(*t, "orm", where, spec.orm)}) {
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
  if (dielectric == "specular") {
    spec.dielectric_f0 = exporter::DielectricF0::specular;
  } else if (dielectric == "ior") {
    spec.dielectric_f0 = exporter::DielectricF0::ior;
  } else if (dielectric == "none") {
    spec.dielectric_f0 = exporter::DielectricF0::none;
  } else {
    return r.at(*t->get("dielectric_f0"), where + ".dielectric_f0 '" + dielectric + "': use specular, ior or none");
  }
  if (const toml::node* mats = t->get("materials")) {
    if (!mats->is_table()) return r.at(*mats, where + ".materials must be a table: { \"glTF name\" = \"material\" }");
    for (const auto& [key, value] : *mats->as_table()) {
      auto target = value.value<std::string>();
      if (!target) return r.at(value, where + ".materials: a manifest material's name expected");
      spec.materials[std::string(key.str())] = *target;
    }
  }
  if (const toml::node* a = t->get("ao")) {
    const toml::table* at = a->as_table();
    const std::string w = where + ".ao";
    if (!at) return r.at(*a, w + " must be a table");
    if (Status s = r.known_keys(*at, w, {"samples", "distance", "absolute_distance", "falloff", "two_sided", "seed",
                                         "sampler", "into", "existing_colors", "fast_traversal"});
        !s) {
      return s.error();
    }
    ao::Options o;
    std::int64_t samples = o.samples, seed = 0;
    double absolute = 0;
    bool fast = false;
    std::string falloff = "exponential", sampler = "sobol", into = "COLOR_0", existing = "multiply";
    for (Status s : {r.get(*at, "samples", w, samples), r.get(*at, "distance", w, o.max_distance),
                     r.get(*at, "absolute_distance", w, absolute), r.get(*at, "falloff", w, falloff),
                     r.get(*at, "two_sided", w, o.two_sided), r.get(*at, "seed", w, seed),
                     r.get(*at, "sampler", w, sampler), r.get(*at, "into", w, into),
                     r.get(*at, "existing_colors", w, existing), r.get(*at, "fast_traversal", w, fast)}) {
      if (!s) return s.error();
    }
    if (samples < 1 || samples > (1 << 20)) return r.at(*a, w + ".samples: 1 to 1048576");
    o.samples = int(samples);
    o.seed = std::uint64_t(seed);
    o.watertight = !fast;
    if (absolute > 0) {
      o.max_distance = absolute;
      o.relative_distance = false;
    }
    if (!(o.max_distance > 0)) return r.at(*a, w + ": distances must be > 0");
    if (falloff != "exponential" && falloff != "none") return r.at(*a, w + ".falloff '" + falloff + "': exponential or none");
    o.falloff = falloff == "none" ? ao::Falloff::none : ao::Falloff::exponential;
    if (sampler != "sobol" && sampler != "random") return r.at(*a, w + ".sampler '" + sampler + "': sobol or random");
    o.sampler = sampler == "random" ? ao::Sampler::random : ao::Sampler::sobol;
    if (into == "_AO") {
      spec.ao_into = ao::Into::attribute;
    } else if (into == "COLOR_0" && (existing == "multiply" || existing == "replace")) {
      spec.ao_into = existing == "multiply" ? ao::Into::color_multiply : ao::Into::color;
    } else {
      return r.at(*a, w + ": into = \"COLOR_0\" (existing_colors = \"multiply\" or \"replace\") or \"_AO\"");
    }
    spec.ao = o;
  }
  return spec;
}

}  // namespace

Result<Manifest> parse_manifest(std::string_view toml_text, const fs::path& file) {
  Manifest m;
  std::error_code ec;
  m.file = fs::absolute(file, ec).lexically_normal();
  m.folder = m.file.parent_path();
  const Reader r{file.string()};
  toml::table doc;
  try {
    doc = toml::parse(toml_text, file.string());
  } catch (const toml::parse_error& e) {
    return Error{file.string() + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column),
                 "not valid TOML: " + std::string(e.description())};
  }
  if (Status s = r.known_keys(doc, "the manifest", {"output", "table", "transfer", "validate", "materials", "scenes"}); !s) {
    return s.error();
  }
  std::string output = "out", table;
  if (Status s = r.get(doc, "output", "manifest", output); !s) return s.error();
  if (Status s = r.get(doc, "table", "manifest", table); !s) return s.error();
  m.output = (m.folder / output).lexically_normal();
  if (!table.empty()) m.table = m.folder / table;
  color::Transfer transfer = color::Transfer::srgb;
  if (Status s = read_transfer(r, doc, "manifest", transfer); !s) return s.error();
  ValidationRules rules;
  if (const toml::node* v = doc.get("validate")) {
    if (!v->is_table()) return r.at(*v, "validate must be a table");
    if (Status s = read_validation(r, *v->as_table(), "validate", rules); !s) return s.error();
  }
  if (const toml::node* mats = doc.get("materials")) {
    if (!mats->is_table()) return r.at(*mats, "materials must be a table of tables: [materials.NAME]");
    for (const auto& [key, value] : *mats->as_table()) {
      auto spec = read_material(r, std::string(key.str()), value, m, transfer, rules);
      if (!spec) return spec.error();
      m.materials.push_back(std::move(*spec));
    }
  }
  if (const toml::node* scenes = doc.get("scenes")) {
    if (!scenes->is_table()) return r.at(*scenes, "scenes must be a table of tables: [scenes.NAME]");
    for (const auto& [key, value] : *scenes->as_table()) {
      auto spec = read_scene(r, std::string(key.str()), value, m);
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
        return Error{file.string(), "scenes." + s.name + ".materials: '" + gltf_name + "' = '" + material +
                                        "', but there is no [materials." + material + "]"};
      }
    }
  }
  return m;
}

Result<Manifest> read_manifest(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return Error{file.string(), "cannot read the manifest (missing or unreadable)"};
  std::ostringstream text;
  text << in.rdbuf();
  return parse_manifest(text.str(), file);
}

}  // namespace matbake::build
