#include "references.hpp"

#include <optional>

namespace matbake::gltf {
namespace {

// A key as a JSON pointer token (RFC 6901): ~ and / escaped.
std::string token(const std::string& key) {
  std::string out;
  for (const char c : key) {
    if (c == '~') {
      out += "~0";
    } else if (c == '/') {
      out += "~1";
    } else {
      out += c;
    }
  }
  return out;
}

std::string item(const std::string& pointer, std::size_t i) { return pointer + "/" + std::to_string(i); }
std::string member(const std::string& pointer, const std::string& key) { return pointer + "/" + token(key); }

const Json& object_at(const Json& json, const char* key) {
  static const Json empty = Json::object();
  const auto it = json.is_object() ? json.find(key) : json.end();
  return it != json.end() && it->is_object() ? *it : empty;
}

const Json& extension(const Json& object, const char* name) { return object_at(object_at(object, "extensions"), name); }

struct Checker {
  const std::string& file;
  const Json& root;
  std::optional<Error> first;  // the first bad reference found

  // `holder[key]`, when present, must index `target` (an array; absent counts as empty).
  void index(const Json& holder, const char* key, const std::string& pointer, const Json& target, const char* kind) {
    if (first || !holder.is_object()) return;
    const auto it = holder.find(key);
    if (it != holder.end()) check(*it, member(pointer, key), target, kind);
  }
  void check(const Json& value, const std::string& pointer, const Json& target, const char* kind) {
    if (first) return;
    const std::size_t count = target.is_array() ? target.size() : 0;
    if (!value.is_number_integer() || value.get<long long>() < 0) {
      first = Error{file, pointer + ": " + value.dump() + " is not an index (a whole number from 0)"};
    } else if (value.get<unsigned long long>() >= count) {
      first = Error{file, pointer + ": " + std::string(kind) + " " + value.dump() + " does not exist (the file has " +
                              std::to_string(count) + ")"};
    }
  }
  // Every element of holder[key] (an array of indices).
  void indices(const Json& holder, const char* key, const std::string& pointer, const Json& target, const char* kind) {
    const Json& list = array_in(holder, key);
    for (std::size_t i = 0; i < list.size(); ++i) check(list[i], item(member(pointer, key), i), target, kind);
  }
  // Every value of holder[key] (an object of name → index: attributes).
  void values(const Json& holder, const char* key, const std::string& pointer, const Json& target, const char* kind) {
    values_in(object_at(holder, key), member(pointer, key), target, kind);
  }
  void values_in(const Json& object, const std::string& pointer, const Json& target, const char* kind) {
    if (!object.is_object()) return;
    for (const auto& [name, value] : object.items()) check(value, member(pointer, name), target, kind);
  }
  const Json& top(const char* key) const { return array_in(root, key); }

  void texture_infos(const Json& json, const std::string& pointer) {
    if (json.is_array()) {
      for (std::size_t i = 0; i < json.size(); ++i) texture_infos(json[i], item(pointer, i));
      return;
    }
    if (!json.is_object()) return;
    for (const auto& [key, value] : json.items()) {
      if (key.ends_with("Texture") && value.is_object()) index(value, "index", member(pointer, key), top("textures"), "texture");
      texture_infos(value, member(pointer, key));
    }
  }

  void nodes() {
    const Json& list = top("nodes");
    const Json& lights = array_in(extension(root, "KHR_lights_punctual"), "lights");
    for (std::size_t n = 0; n < list.size(); ++n) {
      const std::string at = item("/nodes", n);
      index(list[n], "camera", at, top("cameras"), "camera");
      index(list[n], "skin", at, top("skins"), "skin");
      index(list[n], "mesh", at, top("meshes"), "mesh");
      indices(list[n], "children", at, top("nodes"), "node");
      values(extension(list[n], "EXT_mesh_gpu_instancing"), "attributes", at + "/extensions/EXT_mesh_gpu_instancing",
             top("accessors"), "accessor");
      index(extension(list[n], "KHR_lights_punctual"), "light", at + "/extensions/KHR_lights_punctual", lights, "light");
    }
  }

  void primitive(const Json& p, const std::string& at) {
    index(p, "indices", at, top("accessors"), "accessor");
    values(p, "attributes", at, top("accessors"), "accessor");
    const Json& targets = array_in(p, "targets");
    for (std::size_t t = 0; t < targets.size(); ++t) values_in(targets[t], item(at + "/targets", t), top("accessors"), "accessor");
    index(p, "material", at, top("materials"), "material");
    index(extension(p, "KHR_draco_mesh_compression"), "bufferView", at + "/extensions/KHR_draco_mesh_compression",
          top("bufferViews"), "buffer view");
    const Json& variants = array_in(extension(root, "KHR_materials_variants"), "variants");
    const Json& mappings = array_in(extension(p, "KHR_materials_variants"), "mappings");
    for (std::size_t m = 0; m < mappings.size(); ++m) {
      const std::string mapping = item(at + "/extensions/KHR_materials_variants/mappings", m);
      index(mappings[m], "material", mapping, top("materials"), "material");
      indices(mappings[m], "variants", mapping, variants, "variant");
    }
  }

  void meshes() {
    const Json& list = top("meshes");
    for (std::size_t m = 0; m < list.size(); ++m) {
      const Json& primitives = array_in(list[m], "primitives");
      for (std::size_t p = 0; p < primitives.size(); ++p) primitive(primitives[p], item(item("/meshes", m) + "/primitives", p));
    }
  }

  void textures_and_images() {
    const Json& textures = top("textures");
    for (std::size_t t = 0; t < textures.size(); ++t) {
      const std::string at = item("/textures", t);
      index(textures[t], "sampler", at, top("samplers"), "sampler");
      index(textures[t], "source", at, top("images"), "image");
      for (const auto& [name, ext] : object_at(textures[t], "extensions").items()) {
        index(ext, "source", member(at + "/extensions", name), top("images"), "image");
      }
    }
    const Json& images = top("images");
    for (std::size_t i = 0; i < images.size(); ++i) index(images[i], "bufferView", item("/images", i), top("bufferViews"), "buffer view");
  }

  void accessors_and_views() {
    const Json& accessors = top("accessors");
    for (std::size_t a = 0; a < accessors.size(); ++a) {
      const std::string at = item("/accessors", a);
      index(accessors[a], "bufferView", at, top("bufferViews"), "buffer view");
      const Json& sparse = object_at(accessors[a], "sparse");
      index(object_at(sparse, "indices"), "bufferView", at + "/sparse/indices", top("bufferViews"), "buffer view");
      index(object_at(sparse, "values"), "bufferView", at + "/sparse/values", top("bufferViews"), "buffer view");
    }
    const Json& views = top("bufferViews");
    for (std::size_t v = 0; v < views.size(); ++v) {
      const std::string at = item("/bufferViews", v);
      index(views[v], "buffer", at, top("buffers"), "buffer");
      for (const char* name : {"EXT_meshopt_compression", "KHR_meshopt_compression"}) {
        index(extension(views[v], name), "buffer", at + "/extensions/" + name, top("buffers"), "buffer");
      }
    }
  }

  void skins_and_animations() {
    const Json& skins = top("skins");
    for (std::size_t s = 0; s < skins.size(); ++s) {
      const std::string at = item("/skins", s);
      index(skins[s], "inverseBindMatrices", at, top("accessors"), "accessor");
      index(skins[s], "skeleton", at, top("nodes"), "node");
      indices(skins[s], "joints", at, top("nodes"), "node");
    }
    const Json& animations = top("animations");
    for (std::size_t a = 0; a < animations.size(); ++a) {
      const std::string at = item("/animations", a);
      const Json& samplers = array_in(animations[a], "samplers");
      for (std::size_t s = 0; s < samplers.size(); ++s) {
        index(samplers[s], "input", item(at + "/samplers", s), top("accessors"), "accessor");
        index(samplers[s], "output", item(at + "/samplers", s), top("accessors"), "accessor");
      }
      const Json& channels = array_in(animations[a], "channels");
      for (std::size_t c = 0; c < channels.size(); ++c) {
        index(channels[c], "sampler", item(at + "/channels", c), samplers, "animation sampler");
        index(object_at(channels[c], "target"), "node", item(at + "/channels", c) + "/target", top("nodes"), "node");
      }
    }
  }
};

}  // namespace

Status check_references(const std::string& file, const Json& json) {
  Checker checker{file, json, std::nullopt};
  checker.index(json, "scene", "", checker.top("scenes"), "scene");
  const Json& scenes = checker.top("scenes");
  for (std::size_t s = 0; s < scenes.size(); ++s) checker.indices(scenes[s], "nodes", item("/scenes", s), checker.top("nodes"), "node");
  checker.nodes();
  checker.meshes();
  const Json& materials = checker.top("materials");
  for (std::size_t m = 0; m < materials.size(); ++m) checker.texture_infos(materials[m], item("/materials", m));
  checker.textures_and_images();
  checker.accessors_and_views();
  checker.skins_and_animations();
  if (checker.first) return *checker.first;
  return success();
}

}  // namespace matbake::gltf
