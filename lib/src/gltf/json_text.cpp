#include "json_text.hpp"

#include <charconv>
#include <cmath>

namespace matbake::gltf {
namespace {

void add_number(std::string& out, double d) {
  if (!std::isfinite(d)) {
    out += "null";
    return;
  }
  char text[32];
  const float f = float(d);
  // Shortest round trip: of the float32 when the double is one exactly, else of the double.
  const auto end = double(f) == d ? std::to_chars(text, text + sizeof text, f).ptr : std::to_chars(text, text + sizeof text, d).ptr;
  out.append(text, end);
}

void add_text(std::string& out, const Json& json, int indent, int depth) {
  const auto new_line = [&](int level) {
    if (indent < 0) return;
    out += '\n';
    out.append(std::size_t(indent) * std::size_t(level), ' ');
  };
  switch (json.type()) {
    case Json::value_t::object: {
      if (json.empty()) {
        out += "{}";
        return;
      }
      out += '{';
      bool first = true;
      for (const auto& [key, value] : json.items()) {
        if (!first) out += ',';
        first = false;
        new_line(depth + 1);
        out += Json(key).dump();
        out += indent < 0 ? ":" : ": ";
        add_text(out, value, indent, depth + 1);
      }
      new_line(depth);
      out += '}';
      return;
    }
    case Json::value_t::array: {
      if (json.empty()) {
        out += "[]";
        return;
      }
      out += '[';
      for (std::size_t i = 0; i < json.size(); ++i) {
        if (i > 0) out += ',';
        new_line(depth + 1);
        add_text(out, json[i], indent, depth + 1);
      }
      new_line(depth);
      out += ']';
      return;
    }
    case Json::value_t::number_float:
      add_number(out, json.get<double>());
      return;
    default:  // strings (escaped as dump escapes them), integers, booleans, null
      out += json.dump();
  }
}

}  // namespace

std::string json_text(const Json& json, int indent) {
  std::string out;
  add_text(out, json, indent, 0);
  return out;
}

}  // namespace matbake::gltf
