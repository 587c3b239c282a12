#include "matbake/join.hpp"
#include "matbake/params.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>


namespace matbake::params {
namespace {

std::string number_text(double x) {
  char text[32];
  if (x == std::trunc(x) && std::abs(x) < 1e16) {
    std::snprintf(text, sizeof text, "%.0f", x);
  } else {
    std::snprintf(text, sizeof text, "%.6g", x);
  }
  return text;
}

bool has_range(const Spec& spec) { return !(spec.min == 0 && spec.max == 0); }

std::string range_text(const Spec& spec) {
  if (!has_range(spec)) return "";
  if (std::isinf(spec.max)) return (spec.above_min ? "above " : "at least ") + number_text(spec.min);
  return number_text(spec.min) + " to " + number_text(spec.max);
}

bool in_range(const Spec& spec, double x) {
  if (!has_range(spec)) return true;
  return (spec.above_min ? x > spec.min : x >= spec.min) && x <= spec.max;
}

std::string choices_text(const Spec& spec, std::string_view last_joiner) {
  std::string out;
  for (std::size_t i = 0; i < spec.choices.size(); ++i) {
    out += (i == 0 ? "" : i + 1 == spec.choices.size() ? std::string(last_joiner) : ", ") + spec.choices[i];
  }
  return out;
}

std::optional<std::int64_t> integer_from(std::string_view text) {
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return v;
}

}  // namespace

namespace {

// Whether the comma-separated `list` holds one of the comma-separated `names`.
bool holds_any(const std::string& list, const std::string& names) {
  const std::vector<std::string> items = split(list, ',');
  return std::ranges::any_of(split(names, ','), [&](const std::string& n) { return std::ranges::find(items, n) != items.end(); });
}

// "normal or bent_normal" for "normal,bent_normal".
std::string alternatives(const std::string& names) { return join(split(names, ','), " or "); }

}  // namespace

std::optional<RuleBreak> check_rules(const std::vector<GroupState>& groups, const Spelling& spell) {
  struct Found {
    std::size_t group;
    const Spec* spec;
  };
  const auto find = [&](std::size_t own, const std::string& name) -> std::optional<Found> {
    for (std::size_t k = 0; k <= groups.size(); ++k) {  // its own group first, then each in order
      const std::size_t g = k == 0 ? own : k - 1;
      for (const Spec* s : groups[g].specs) {
        if (s->name == name) return Found{g, s};
      }
    }
    return std::nullopt;
  };
  for (std::size_t g = 0; g < groups.size(); ++g) {
    for (const Spec* spec : groups[g].specs) {
      if (!groups[g].given.count(spec->name)) continue;
      const std::string self = spell(g, *spec, nullptr);
      for (const std::string& other : spec->excludes) {
        const auto o = find(g, other);
        if (o && groups[o->group].given.count(other)) {
          return RuleBreak{g, spec->name, self + " and " + spell(o->group, *o->spec, nullptr) + " cannot be given together"};
        }
      }
      for (const Condition& c : spec->needs) {
        const auto needed = find(g, c.name);
        if (!needed) continue;
        const GroupState& in = groups[needed->group];
        const std::string value = value_text(in.values.value(c.name, nlohmann::json()));
        if (c.among) {
          if (!groups[g].inherited.count(spec->name) && !holds_any(value, c.value)) {
            return RuleBreak{g, spec->name, self + " applies only with " + alternatives(c.value) + " among " + spell(needed->group, *needed->spec, nullptr)};
          }
          continue;
        }
        if (c.value.empty() ? !in.given.count(c.name) : value != c.value) {
          return RuleBreak{g, spec->name, self + " applies only with " + spell(needed->group, *needed->spec, c.value.empty() ? nullptr : &c.value) +
                                              (c.value.empty() ? " as well" : "")};
        }
      }
    }
  }
  return std::nullopt;
}

std::string toml_value_text(const Spec& spec, const std::string& value) {
  const bool bare = spec.kind == Kind::flag || spec.kind == Kind::integer || spec.kind == Kind::number ||
                    (spec.kind == Kind::integer_or_text && integer_from(value));
  return bare ? value : "\"" + value + "\"";
}

std::string flag_name(const Spec& spec, std::string_view prefix) {
  std::string name = "--" + std::string(prefix) + spec.name;
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}

Result<Value> from_text(const Spec& spec, std::string_view text) {
  switch (spec.kind) {
    case Kind::flag:
      if (text == "true" || text.empty()) return Value(true);
      if (text == "false") return Value(false);
      return Error{"", "true or false expected", true};
    case Kind::integer:
      if (auto v = integer_from(text)) return Value(*v);
      return Error{"", "an integer expected", true};
    case Kind::number: {
      const std::string s(text);
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty() || end != s.c_str() + s.size()) return Error{"", "a number expected", true};
      return Value(v);
    }
    case Kind::integer_or_text:
      if (auto v = integer_from(text)) return Value(*v);
      return Value(std::string(text));
    case Kind::text:
    case Kind::choice: return Value(std::string(text));
  }
  return Error{"", "unknown kind", true};
}

Result<Value> accept(const Spec& spec, Value value) {
  const auto out_of_range = [&](double x) { return !in_range(spec, x); };
  switch (spec.kind) {
    case Kind::flag:
      if (std::holds_alternative<bool>(value)) return value;
      return Error{"", "true or false expected", true};
    case Kind::integer:
      if (!std::holds_alternative<std::int64_t>(value)) return Error{"", "an integer expected", true};
      if (out_of_range(double(std::get<std::int64_t>(value)))) return Error{"", range_text(spec), true};
      return value;
    case Kind::number: {
      if (const auto* i = std::get_if<std::int64_t>(&value)) value = double(*i);
      if (!std::holds_alternative<double>(value)) return Error{"", "a number expected", true};
      const double x = std::get<double>(value);
      if (!std::isfinite(x) || out_of_range(x)) {
        return Error{"", has_range(spec) ? range_text(spec) : std::string("a finite number expected"), true};
      }
      return value;
    }
    case Kind::text:
      if (std::holds_alternative<std::string>(value)) return value;
      return Error{"", "a string expected", true};
    case Kind::choice: {
      const std::string* name = std::get_if<std::string>(&value);
      if (!name || std::find(spec.choices.begin(), spec.choices.end(), *name) == spec.choices.end()) {
        return Error{"", "use " + choices_text(spec, " or "), true};
      }
      return value;
    }
    case Kind::integer_or_text:
      if (std::holds_alternative<std::int64_t>(value) || std::holds_alternative<std::string>(value)) return value;
      return Error{"", "an integer or a string expected", true};
  }
  return Error{"", "unknown kind", true};
}

std::string type_text(const Spec& spec) {
  switch (spec.kind) {
    case Kind::flag: return "true/false";
    case Kind::integer: return has_range(spec) ? "integer, " + range_text(spec) : "integer";
    case Kind::number: return has_range(spec) ? "number, " + range_text(spec) : "number";
    case Kind::text: return "text";
    case Kind::choice: return choices_text(spec, ", ");
    case Kind::integer_or_text: return "integer or text";
  }
  return "";
}

std::string value_text(const nlohmann::json& value) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number()) return number_text(value.get<double>());
  return value.dump();
}

// The docs' words for a parameter's rules: " (with `texture`; not with `into`)".
std::string rules_text(const Spec& spec) {
  std::vector<std::string> parts;
  for (const Condition& c : spec.needs) {
    parts.push_back(c.among ? "with " + alternatives(c.value) + " among `" + c.name + "`"
                            : "with `" + c.name + (c.value.empty() ? "" : " = " + c.value) + "`");
  }
  for (const std::string& other : spec.excludes) parts.push_back("not with `" + other + "`");
  return parts.empty() ? "" : " (" + join(parts, "; ") + ")";
}

std::string markdown_table(const std::vector<const Spec*>& specs, const nlohmann::json& defaults,
                           std::string_view flag_prefix) {
  std::string out = "| flag | manifest key | type | default | what it does |\n|---|---|---|---|---|\n";
  for (const Spec* s : specs) {
    const nlohmann::json& d = defaults.at(s->name);
    const std::string shown = d.is_null() ? "unset" : value_text(d);
    const bool off_flag = s->kind == Kind::flag && d.is_boolean() && d.get<bool>();
    const std::string flag = flag_name(*s, flag_prefix);
    const std::string shown_flag = s->manifest_only ? "—" : "`" + (off_flag ? "--no-" + flag.substr(2) : flag) + "`";
    out += "| " + shown_flag + " | `" + s->name + "` | " + type_text(*s) + " | " + shown + " | " + s->help + rules_text(*s) +
           (s->aliases.empty() ? "" : "; older key: `" + s->aliases.front() + "`") + " |\n";
  }
  return out;
}

}  // namespace matbake::params
