#include "matbake/join.hpp"
#include "matbake/read_file.hpp"
#include "matbake/material_table.hpp"
#include "matbake/near_names.hpp"
#include "../io/bounded_toml.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <stdexcept>
#include <fstream>
#include <sstream>

namespace matbake::material_table {

extern const char* const builtin_table_toml;  // generated from presets/materials.toml

namespace {

Result<Vec3> read_rgb(const toml::table& entry, std::string_view key, const std::string& origin,
                      const std::string& name) {
  const toml::array* a = entry[key].as_array();
  if (!a || a->size() != 3) return Error{origin, name + ": \"" + std::string(key) + "\" must be 3 numbers"};
  Vec3 v;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto x = (*a)[i].value<double>();
    if (!x) return Error{origin, name + ": \"" + std::string(key) + "\" must be 3 numbers"};
    v[int(i)] = *x;
  }
  return v;
}

}  // namespace

std::string_view class_name(MaterialClass c) {
  switch (c) {
    case MaterialClass::dielectric: return "dielectric";
    case MaterialClass::gem: return "gem";
    case MaterialClass::semiconductor: return "semiconductor";
    case MaterialClass::metal: return "metal";
  }
  return "";
}

std::string_view f0_class_name(F0Class c) {
  switch (c) {
    case F0Class::below: return "below";
    case F0Class::dielectric: return "dielectric";
    case F0Class::gem: return "gem";
    case F0Class::semiconductor: return "semiconductor";
    case F0Class::metal: return "metal";
  }
  return "";
}

Result<std::vector<Material>> parse_table(std::string_view toml_text, const std::string& origin) {
  return guarded(origin, [&]() -> Result<std::vector<Material>> {
    toml::table doc;
    const TomlDepth depth = toml_key_depth(toml_text);
    if (std::string problem = toml_depth_problem(depth); !problem.empty()) {
      return Error{origin, problem + " (line " + std::to_string(depth.line) + ")"};
    }
    try {
      doc = toml::parse(toml_text, origin);
    } catch (const toml::parse_error& e) {
      return Error{origin, "not valid TOML: " + std::string(e.description()) + " (line " +
                               std::to_string(e.source().begin.line) + ")"};
    }
    const toml::array* entries = doc["material"].as_array();
    if (!entries || entries->empty()) return Error{origin, "no [[material]] entries"};
    std::vector<Material> table;
    for (std::size_t i = 0; i < entries->size(); ++i) {
      const toml::table* entry = (*entries)[i].as_table();
      const std::string where = "entry " + std::to_string(i + 1);
      if (!entry) return Error{origin, where + ": not a table"};
      Material m;
      m.name = entry->get("name") ? (*entry)["name"].value_or(std::string()) : "";
      if (m.name.empty()) return Error{origin, where + ": needs a \"name\""};
      if (find(table, m.name)) return Error{origin, m.name + ": listed twice"};
      const std::string cls = (*entry)["class"].value_or(std::string());
      if (cls == "dielectric") {
        m.material_class = MaterialClass::dielectric;
      } else if (cls == "gem") {
        m.material_class = MaterialClass::gem;
      } else if (cls == "semiconductor") {
        m.material_class = MaterialClass::semiconductor;
      } else if (cls == "metal") {
        m.material_class = MaterialClass::metal;
      } else {
        return Error{origin, m.name + ": \"class\" must be dielectric, gem, semiconductor or metal"};
      }
      auto f0 = read_rgb(*entry, "f0", origin, m.name);
      if (!f0) return f0.error();
      m.f0 = *f0;
      for (int c = 0; c < 3; ++c) {
        if (!(m.f0[c] >= 0 && m.f0[c] <= 1)) return Error{origin, m.name + ": f0 outside [0, 1]"};
      }
      if (const toml::array* range = (*entry)["f0_range"].as_array()) {
        if (range->size() != 2 || !(*range)[0].is_number() || !(*range)[1].is_number()) {
          return Error{origin, m.name + ": \"f0_range\" must be 2 numbers"};
        }
        m.f0_range = std::array<double, 2>{*(*range)[0].value<double>(), *(*range)[1].value<double>()};
      }
      if (const toml::array* code = (*entry)["table_code"].as_array()) {
        // Integer nodes only (toml++ 3.3 casts a float such as 2e52 to int64 unchecked, undefined
        // behaviour found by fuzzing); a code is 0 to 255, anything else is -1 (no code).
        for (const auto& c : *code) {
          const std::int64_t v = c.is_integer() ? c.as_integer()->get() : -1;
          m.table_code.push_back(v >= 0 && v <= 255 ? int(v) : -1);
        }
      }
      m.ior = (*entry)["ior"].value<double>();
      if (entry->contains("ior_n") || entry->contains("ior_k")) {
        auto n = read_rgb(*entry, "ior_n", origin, m.name);
        if (!n) return n.error();
        auto k = read_rgb(*entry, "ior_k", origin, m.name);
        if (!k) return k.error();
        m.ior_n = *n;
        m.ior_k = *k;
      }
      m.source = (*entry)["source"].value_or(std::string());
      if (m.source.empty()) return Error{origin, m.name + ": needs a \"source\" (a fact with a citation)"};
      table.push_back(std::move(m));
    }
    return table;
  });
}

Result<std::vector<Material>> load_table(const std::filesystem::path& path) {
  std::string text;
  if (!read_whole_file(path, text)) return Error{path.string(), "cannot read (missing, unreadable or not a file)"};
  return parse_table(text, path.string());
}

const std::vector<Material>& builtin_table() {
  static const std::vector<Material> table = [] {
    auto parsed = parse_table(builtin_table_toml, "presets/materials.toml");
    // The shipped file is checked by the tests; a broken build of it is a programming error.
    if (!parsed) throw std::logic_error(parsed.error().to_string());
    return std::move(parsed.value());
  }();
  return table;
}

const Material* find(const std::vector<Material>& table, std::string_view name) {
  for (const Material& m : table) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::vector<std::string> near_names(const std::vector<Material>& table, std::string_view name) {
  std::vector<std::string> names;
  for (const Material& m : table) names.push_back(m.name);
  return matbake::near_names(name, names);
}

Result<const Material*> lookup(const std::vector<Material>& table, std::string_view name) {
  if (const Material* m = find(table, name)) return m;
  const std::string near = join(near_names(table, name), ", ");
  return Error{"", "unknown material '" + std::string(name) + "'" +
                       (near.empty() ? " (`matbake materials` lists them)" : "; near: " + near), true};
}

Result<std::vector<Material>> table_or_builtin(const std::filesystem::path& path) {
  if (path.empty()) return builtin_table();
  return load_table(path);
}

}  // namespace matbake::material_table
