#include "types.hpp"

#include <optional>
#include <sstream>
#include <vector>

namespace matbake::gltf {
namespace {

enum class Kind { object, array, text, whole, number, boolean };

// One property of the core schema: where (names separated by '/'; '*' is every item of an array or
// member of an object), its type, an array's length (0: any) and the values allowed (space-separated;
// none: any of its type).
struct Rule {
  std::string path;
  Kind kind;
  std::size_t length = 0;
  std::string allowed;
};

constexpr const char* kTopArrays[] = {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials",
                                      "meshes",    "nodes",      "samplers", "scenes",     "skins",   "textures"};

void add_numbers(std::vector<Rule>& rules, const std::string& path, std::size_t length) {
  rules.push_back({path, Kind::array, length, {}});
  rules.push_back({path + "/*", Kind::number, 0, {}});
}

void add_wholes(std::vector<Rule>& rules, const std::string& path) {
  rules.push_back({path, Kind::array, 0, {}});
  rules.push_back({path + "/*", Kind::whole, 0, {}});
}

void add_texture_info(std::vector<Rule>& rules, const std::string& path) {
  rules.push_back({path, Kind::object, 0, {}});
  rules.push_back({path + "/index", Kind::whole, 0, {}});
  rules.push_back({path + "/texCoord", Kind::whole, 0, {}});
  rules.push_back({path + "/extensions", Kind::object, 0, {}});
}

std::vector<Rule> accessor_rules() {
  std::vector<Rule> r = {
      {"accessors/*/bufferView", Kind::whole},
      {"accessors/*/byteOffset", Kind::whole},
      {"accessors/*/componentType", Kind::whole, 0, "5120 5121 5122 5123 5125 5126"},
      {"accessors/*/normalized", Kind::boolean},
      {"accessors/*/count", Kind::whole},
      {"accessors/*/type", Kind::text, 0, "SCALAR VEC2 VEC3 VEC4 MAT2 MAT3 MAT4"},
      {"accessors/*/sparse", Kind::object},
      {"accessors/*/sparse/count", Kind::whole},
      {"accessors/*/sparse/indices", Kind::object},
      {"accessors/*/sparse/indices/bufferView", Kind::whole},
      {"accessors/*/sparse/indices/byteOffset", Kind::whole},
      {"accessors/*/sparse/indices/componentType", Kind::whole, 0, "5121 5123 5125"},
      {"accessors/*/sparse/values", Kind::object},
      {"accessors/*/sparse/values/bufferView", Kind::whole},
      {"accessors/*/sparse/values/byteOffset", Kind::whole},
      {"bufferViews/*/buffer", Kind::whole},
      {"bufferViews/*/byteOffset", Kind::whole},
      {"bufferViews/*/byteLength", Kind::whole},
      {"bufferViews/*/byteStride", Kind::whole},
      {"bufferViews/*/target", Kind::whole, 0, "34962 34963"},
      {"buffers/*/uri", Kind::text},
      {"buffers/*/byteLength", Kind::whole},
  };
  add_numbers(r, "accessors/*/min", 0);
  add_numbers(r, "accessors/*/max", 0);
  return r;
}

std::vector<Rule> material_rules() {
  std::vector<Rule> r = {
      {"materials/*/pbrMetallicRoughness", Kind::object},
      {"materials/*/pbrMetallicRoughness/metallicFactor", Kind::number},
      {"materials/*/pbrMetallicRoughness/roughnessFactor", Kind::number},
      {"materials/*/pbrMetallicRoughness/extensions", Kind::object},
      {"materials/*/normalTexture/scale", Kind::number},
      {"materials/*/occlusionTexture/strength", Kind::number},
      {"materials/*/alphaMode", Kind::text, 0, "OPAQUE MASK BLEND"},
      {"materials/*/alphaCutoff", Kind::number},
      {"materials/*/doubleSided", Kind::boolean},
  };
  add_numbers(r, "materials/*/pbrMetallicRoughness/baseColorFactor", 4);
  add_numbers(r, "materials/*/emissiveFactor", 3);
  for (const char* info : {"pbrMetallicRoughness/baseColorTexture", "pbrMetallicRoughness/metallicRoughnessTexture",
                           "normalTexture", "occlusionTexture", "emissiveTexture"}) {
    add_texture_info(r, std::string("materials/*/") + info);
  }
  return r;
}

std::vector<Rule> scene_rules() {
  std::vector<Rule> r = {
      {"meshes/*/primitives", Kind::array},
      {"meshes/*/primitives/*", Kind::object},
      {"meshes/*/primitives/*/attributes", Kind::object},
      {"meshes/*/primitives/*/attributes/*", Kind::whole},
      {"meshes/*/primitives/*/indices", Kind::whole},
      {"meshes/*/primitives/*/material", Kind::whole},
      {"meshes/*/primitives/*/mode", Kind::whole, 0, "0 1 2 3 4 5 6"},
      {"meshes/*/primitives/*/targets", Kind::array},
      {"meshes/*/primitives/*/targets/*", Kind::object},
      {"meshes/*/primitives/*/targets/*/*", Kind::whole},
      {"meshes/*/primitives/*/extensions", Kind::object},
      {"nodes/*/camera", Kind::whole},
      {"nodes/*/skin", Kind::whole},
      {"nodes/*/mesh", Kind::whole},
      {"scene", Kind::whole},
      {"cameras/*/type", Kind::text, 0, "perspective orthographic"},
      {"cameras/*/perspective", Kind::object},
      {"cameras/*/orthographic", Kind::object},
      {"images/*/uri", Kind::text},
      {"images/*/mimeType", Kind::text},
      {"images/*/bufferView", Kind::whole},
      {"samplers/*/magFilter", Kind::whole, 0, "9728 9729"},
      {"samplers/*/minFilter", Kind::whole, 0, "9728 9729 9984 9985 9986 9987"},
      {"samplers/*/wrapS", Kind::whole, 0, "33071 33648 10497"},
      {"samplers/*/wrapT", Kind::whole, 0, "33071 33648 10497"},
      {"textures/*/sampler", Kind::whole},
      {"textures/*/source", Kind::whole},
      {"skins/*/inverseBindMatrices", Kind::whole},
      {"skins/*/skeleton", Kind::whole},
      {"animations/*/channels", Kind::array},
      {"animations/*/channels/*", Kind::object},
      {"animations/*/channels/*/sampler", Kind::whole},
      {"animations/*/channels/*/target", Kind::object},
      {"animations/*/channels/*/target/node", Kind::whole},
      {"animations/*/channels/*/target/path", Kind::text},
      {"animations/*/samplers", Kind::array},
      {"animations/*/samplers/*", Kind::object},
      {"animations/*/samplers/*/input", Kind::whole},
      {"animations/*/samplers/*/output", Kind::whole},
      {"animations/*/samplers/*/interpolation", Kind::text, 0, "LINEAR STEP CUBICSPLINE"},
  };
  add_numbers(r, "meshes/*/weights", 0);
  add_numbers(r, "nodes/*/weights", 0);
  add_numbers(r, "nodes/*/matrix", 16);
  add_numbers(r, "nodes/*/rotation", 4);
  add_numbers(r, "nodes/*/scale", 3);
  add_numbers(r, "nodes/*/translation", 3);
  add_wholes(r, "nodes/*/children");
  add_wholes(r, "scenes/*/nodes");
  add_wholes(r, "skins/*/joints");
  for (const char* camera : {"perspective", "orthographic"}) {
    for (const char* value : {"aspectRatio", "yfov", "xmag", "ymag", "zfar", "znear"}) {
      r.push_back({std::string("cameras/*/") + camera + "/" + value, Kind::number});
    }
  }
  return r;
}

// Parents before their members: a member is looked for only in a parent of the right type.
std::vector<Rule> core_rules() {
  std::vector<Rule> r = {{"asset", Kind::object},          {"asset/version", Kind::text}, {"asset/minVersion", Kind::text},
                         {"asset/generator", Kind::text},  {"asset/copyright", Kind::text}, {"extensions", Kind::object},
                         {"extensionsUsed", Kind::array},  {"extensionsUsed/*", Kind::text}, {"extensionsRequired", Kind::array},
                         {"extensionsRequired/*", Kind::text}};
  for (const char* top : kTopArrays) {
    r.push_back({top, Kind::array});
    r.push_back({std::string(top) + "/*", Kind::object});
    r.push_back({std::string(top) + "/*/name", Kind::text});
    r.push_back({std::string(top) + "/*/extensions", Kind::object});
  }
  for (auto part : {accessor_rules(), material_rules(), scene_rules()}) r.insert(r.end(), part.begin(), part.end());
  return r;
}

const char* kind_name(Kind kind) {
  switch (kind) {
    case Kind::object: return "an object";
    case Kind::array: return "an array";
    case Kind::text: return "a string";
    case Kind::whole: return "a whole number from 0";
    case Kind::number: return "a number";
    case Kind::boolean: return "true or false";
  }
  return "";
}

bool is(const Json& value, Kind kind) {
  switch (kind) {
    case Kind::object: return value.is_object();
    case Kind::array: return value.is_array();
    case Kind::text: return value.is_string();
    case Kind::whole: return value.is_number_unsigned() || (value.is_number_integer() && value.get<long long>() >= 0);
    case Kind::number: return value.is_number();
    case Kind::boolean: return value.is_boolean();
  }
  return false;
}

// A value for a message: scalars as written (cut short), containers by their kind.
std::string shown(const Json& value) {
  if (value.is_object()) return "an object";
  if (value.is_array()) return "an array";
  const std::string text = value.dump(-1, ' ', true, Json::error_handler_t::replace);
  return text.size() > 40 ? text.substr(0, 37) + "..." : text;
}

std::optional<std::string> problem(const Json& value, const Rule& rule) {
  if (!is(value, rule.kind)) return shown(value) + " is not " + kind_name(rule.kind);
  if (rule.length && value.size() != rule.length) {
    return "an array of " + std::to_string(value.size()) + " where glTF has " + std::to_string(rule.length);
  }
  if (!rule.allowed.empty()) {
    const std::string text = value.is_string() ? value.get<std::string>() : value.dump();
    std::istringstream words(rule.allowed);
    for (std::string word; words >> word;) {
      if (word == text) return std::nullopt;
    }
    return shown(value) + " is not one of " + rule.allowed;
  }
  return std::nullopt;
}

struct Walk {
  const std::vector<std::string>& names;
  const Rule& rule;
  std::optional<std::string> first;  // "pointer: problem"

  void at(const Json& value, std::size_t depth, const Json::json_pointer& pointer) {
    if (first) return;
    if (depth == names.size()) {
      if (auto why = problem(value, rule)) first = pointer.to_string() + ": " + *why;
      return;
    }
    const std::string& name = names[depth];
    if (name == "*" && value.is_array()) {
      for (std::size_t i = 0; i < value.size(); ++i) at(value[i], depth + 1, pointer / i);
    } else if (name == "*" && value.is_object()) {
      for (const auto& [key, member] : value.items()) at(member, depth + 1, pointer / key);
    } else if (value.is_object() && value.contains(name)) {
      at(value[name], depth + 1, pointer / name);
    }
  }
};

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> names;
  std::istringstream in(path);
  for (std::string name; std::getline(in, name, '/');) names.push_back(name);
  return names;
}

}  // namespace

Status check_types(const std::string& file, const Json& json) {
  static const std::vector<Rule> rules = core_rules();
  for (const Rule& rule : rules) {
    const std::vector<std::string> names = split(rule.path);
    Walk walk{names, rule, std::nullopt};
    walk.at(json, 0, Json::json_pointer());
    if (walk.first) return Error{file, *walk.first};
  }
  return success();
}

}  // namespace matbake::gltf
