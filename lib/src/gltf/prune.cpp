#include "prune.hpp"

#include <functional>
#include <map>
#include <unordered_map>

namespace matbake::gltf {
namespace {

std::size_t count_of(const Json& json, const char* key) { return json.contains(key) ? json[key].size() : 0; }

// A valid index into json[key], or −1.
int index_in(const Json& json, const char* key, const Json& value) {
  if (!value.is_number_integer()) return -1;
  const long long i = value.get<long long>();
  return i >= 0 && std::size_t(i) < count_of(json, key) ? int(i) : -1;
}

// The reachable-or-not flags of one top-level array.
struct Marks {
  const char* key;
  std::vector<bool> keep;
  void mark(const Json& json, const Json& value) {
    if (const int i = index_in(json, key, value); i >= 0) keep[std::size_t(i)] = true;
  }
};

// Keeps the marked items of json[key]; returns old index → new index (−1: removed) and says what went.
std::vector<int> keep_marked(Json& json, const Marks& marks, const char* what, std::vector<std::string>& removed) {
  std::vector<int> remap(marks.keep.size(), -1);
  if (!json.contains(marks.key)) return remap;
  Json kept = Json::array();
  for (std::size_t i = 0; i < marks.keep.size(); ++i) {
    Json& item = json[marks.key][i];
    if (marks.keep[i]) {
      remap[i] = int(kept.size());
      kept.push_back(std::move(item));
    } else {
      const std::string name = name_in(item, "");
      removed.push_back(std::string(what) + " " + std::to_string(i) + (name.empty() ? "" : " '" + name + "'"));
    }
  }
  if (kept.empty()) {
    json.erase(marks.key);
  } else {
    json[marks.key] = std::move(kept);
  }
  return remap;
}

void remap_field(Json& object, const char* field, const std::vector<int>& remap) {
  if (!object.is_object() || !object.contains(field) || !object[field].is_number_integer()) return;
  const long long i = object[field].get<long long>();
  if (i >= 0 && std::size_t(i) < remap.size() && remap[std::size_t(i)] >= 0) {
    object[field] = remap[std::size_t(i)];
  } else {
    object.erase(field);
  }
}

template <class F>
void for_each_in(Json& json, const char* key, F f) {
  if (!json.contains(key)) return;
  for (Json& item : json[key]) f(item);
}

template <class F>
void for_each_primitive(Json& json, F f) {
  for_each_in(json, "meshes", [&](Json& mesh) { for_each_in(mesh, "primitives", f); });
}

// Every accessor a primitive reads: indices, attributes, morph targets.
template <class F>
void for_each_primitive_accessor(Json& primitive, F f) {
  if (primitive.contains("indices")) f(primitive["indices"]);
  if (primitive.contains("attributes")) {
    for (auto& [name, a] : primitive["attributes"].items()) f(a);
  }
  for_each_in(primitive, "targets", [&](Json& target) {
    for (auto& [name, a] : target.items()) f(a);
  });
}

// Materials a primitive names in KHR_materials_variants' mappings, besides its own.
template <class F>
void for_each_variant_material(Json& primitive, F f) {
  if (!primitive.contains("extensions") || !primitive["extensions"].contains("KHR_materials_variants")) return;
  for_each_in(primitive["extensions"]["KHR_materials_variants"], "mappings", [&](Json& mapping) {
    if (mapping.contains("material")) f(mapping["material"]);
  });
}

// Accessors a node reads through EXT_mesh_gpu_instancing (per-instance transforms).
template <class F>
void for_each_node_accessor(Json& node, F f) {
  if (!node.contains("extensions") || !node["extensions"].contains("EXT_mesh_gpu_instancing")) return;
  Json& instancing = node["extensions"]["EXT_mesh_gpu_instancing"];
  if (!instancing.contains("attributes")) return;
  for (auto& [name, a] : instancing["attributes"].items()) f(a);
}

// Every accessor that skins and animations read.
template <class F>
void for_each_other_accessor(Json& json, F f) {
  for_each_in(json, "skins", [&](Json& skin) {
    if (skin.contains("inverseBindMatrices")) f(skin["inverseBindMatrices"]);
  });
  for_each_in(json, "animations", [&](Json& animation) {
    for_each_in(animation, "samplers", [&](Json& sampler) {
      if (sampler.contains("input")) f(sampler["input"]);
      if (sampler.contains("output")) f(sampler["output"]);
    });
  });
}

// Image references of a texture: its source and any extension's (KHR_texture_basisu, EXT_texture_webp).
template <class F>
void for_each_texture_source(Json& texture, F f) {
  if (texture.contains("source")) f(texture["source"]);
  if (texture.contains("extensions")) {
    for (auto& [name, extension] : texture["extensions"].items()) {
      if (extension.is_object() && extension.contains("source")) f(extension["source"]);
    }
  }
}

template <class F>
void for_each_sparse_view(Json& accessor, F f) {
  if (!accessor.contains("sparse")) return;
  Json& sparse = accessor["sparse"];
  if (sparse.contains("indices") && sparse["indices"].contains("bufferView")) f(sparse["indices"]["bufferView"]);
  if (sparse.contains("values") && sparse["values"].contains("bufferView")) f(sparse["values"]["bufferView"]);
}

// The buffer view a primitive's Draco data lies in.
template <class F>
void for_each_draco_view(Json& primitive, F f) {
  if (primitive.contains("extensions") && primitive["extensions"].contains("KHR_draco_mesh_compression")) {
    Json& draco = primitive["extensions"]["KHR_draco_mesh_compression"];
    if (draco.contains("bufferView")) f(draco["bufferView"]);
  }
}

// Decoded bytes follow their accessor or view to its new index (and go with it when it is removed).
void remap_keys(std::map<std::size_t, std::vector<unsigned char>>& decoded, const std::vector<int>& remap) {
  std::map<std::size_t, std::vector<unsigned char>> moved;
  for (auto& [index, bytes] : decoded) {
    if (index < remap.size() && remap[index] >= 0) moved[std::size_t(remap[index])] = std::move(bytes);
  }
  decoded = std::move(moved);
}

void remap_value(Json& value, const std::vector<int>& remap) {
  if (!value.is_number_integer()) return;
  const long long i = value.get<long long>();
  value = i >= 0 && std::size_t(i) < remap.size() ? remap[std::size_t(i)] : -1;
}

}  // namespace

void for_each_texture_info(Json& material, const std::function<void(Json& info)>& f) {
  if (material.is_array()) {
    for (Json& item : material) for_each_texture_info(item, f);
    return;
  }
  if (!material.is_object()) return;
  for (auto& [key, value] : material.items()) {
    if (key.ends_with("Texture") && value.is_object() && value.contains("index")) f(value);
    for_each_texture_info(value, f);
  }
}

void for_each_texture_index(Json& material, const std::function<void(Json&)>& f) {
  for_each_texture_info(material, [&](Json& info) { f(info["index"]); });
}

namespace {

// The reachable-or-not flags of every top-level array prune_unreachable may shorten.
struct AllMarks {
  Marks meshes, materials, accessors, textures, images, samplers, views;
};

// Marks `marks` every item `before` held unreachable (the same index: edits only append).
void keep_unreachable(Marks& marks, const std::vector<bool>* before) {
  if (!before) return;
  for (std::size_t i = 0; i < std::min(before->size(), marks.keep.size()); ++i) {
    if (!(*before)[i]) marks.keep[i] = true;
  }
}

// What the default scene reaches and, with `before`, what was unreachable then, and all that these
// reference: each kind's kept items are added before what they reference is marked, so nothing
// kept loses a reference.
AllMarks mark_reachable(Json& json, const Reachable* before) {
  // Nodes of the default scene (scene 0 when none is named), with a stack rather than recursion (a
  // hostile file may nest a million nodes); cycles stop.
  std::vector<bool> in_scene(count_of(json, "nodes"), false);
  const int scene = json.contains("scene") ? index_in(json, "scenes", json["scene"]) : (count_of(json, "scenes") ? 0 : -1);
  std::vector<int> pending;
  const auto reach = [&](Json& n) {
    if (const int i = index_in(json, "nodes", n); i >= 0 && !in_scene[std::size_t(i)]) {
      in_scene[std::size_t(i)] = true;
      pending.push_back(i);
    }
  };
  if (scene >= 0) for_each_in(json["scenes"][std::size_t(scene)], "nodes", reach);
  while (!pending.empty()) {
    const int i = pending.back();
    pending.pop_back();
    for_each_in(json["nodes"][std::size_t(i)], "children", reach);
  }
  const auto marks = [&](const char* key) { return Marks{key, std::vector<bool>(count_of(json, key))}; };
  AllMarks m{marks("meshes"), marks("materials"), marks("accessors"), marks("textures"),
             marks("images"), marks("samplers"), marks("bufferViews")};
  const auto also = [&](Marks& kind, std::vector<bool> Reachable::*field) {
    keep_unreachable(kind, before ? &(before->*field) : nullptr);
  };
  for (std::size_t n = 0; n < in_scene.size(); ++n) {
    if (in_scene[n] && json["nodes"][n].contains("mesh")) m.meshes.mark(json, json["nodes"][n]["mesh"]);
  }
  also(m.meshes, &Reachable::meshes);
  for (std::size_t i = 0; i < m.meshes.keep.size(); ++i) {
    if (!m.meshes.keep[i]) continue;
    for_each_in(json["meshes"][i], "primitives", [&](Json& p) {
      if (p.contains("material")) m.materials.mark(json, p["material"]);
      for_each_variant_material(p, [&](Json& material) { m.materials.mark(json, material); });
      for_each_primitive_accessor(p, [&](Json& a) { m.accessors.mark(json, a); });
    });
  }
  for (std::size_t n = 0; n < in_scene.size(); ++n) {
    if (in_scene[n]) for_each_node_accessor(json["nodes"][n], [&](Json& a) { m.accessors.mark(json, a); });
  }
  for_each_other_accessor(json, [&](Json& a) { m.accessors.mark(json, a); });
  also(m.materials, &Reachable::materials);
  also(m.accessors, &Reachable::accessors);
  for (std::size_t i = 0; i < m.materials.keep.size(); ++i) {
    if (m.materials.keep[i]) for_each_texture_index(json["materials"][i], [&](Json& t) { m.textures.mark(json, t); });
  }
  also(m.textures, &Reachable::textures);
  for (std::size_t t = 0; t < m.textures.keep.size(); ++t) {
    if (!m.textures.keep[t]) continue;
    Json& texture = json["textures"][t];
    for_each_texture_source(texture, [&](Json& i) { m.images.mark(json, i); });
    if (texture.contains("sampler")) m.samplers.mark(json, texture["sampler"]);
  }
  also(m.images, &Reachable::images);
  also(m.samplers, &Reachable::samplers);
  for (std::size_t a = 0; a < m.accessors.keep.size(); ++a) {
    if (!m.accessors.keep[a]) continue;
    Json& accessor = json["accessors"][a];
    if (accessor.contains("bufferView")) m.views.mark(json, accessor["bufferView"]);
    for_each_sparse_view(accessor, [&](Json& v) { m.views.mark(json, v); });
  }
  for (std::size_t i = 0; i < m.images.keep.size(); ++i) {
    if (m.images.keep[i] && json["images"][i].contains("bufferView")) m.views.mark(json, json["images"][i]["bufferView"]);
  }
  for (std::size_t i = 0; i < m.meshes.keep.size(); ++i) {
    if (m.meshes.keep[i]) for_each_in(json["meshes"][i], "primitives", [&](Json& p) { for_each_draco_view(p, [&](Json& v) { m.views.mark(json, v); }); });
  }
  also(m.views, &Reachable::views);
  return m;
}

}  // namespace

Reachable reachable(Json& json) {
  const AllMarks m = mark_reachable(json, nullptr);
  return {m.meshes.keep, m.materials.keep, m.accessors.keep, m.textures.keep, m.images.keep, m.samplers.keep, m.views.keep};
}

std::vector<std::string> prune_unreachable(Document& doc, std::vector<int>* texture_remap_out, const Reachable* before) {
  Json& json = doc.json;
  std::vector<std::string> removed;
  AllMarks marks = mark_reachable(json, before);
  auto& [meshes, materials, accessors, textures, images, samplers, views] = marks;

  // Remove, then point every reference at the new indices.
  const auto mesh_remap = keep_marked(json, meshes, "mesh", removed);
  const auto material_remap = keep_marked(json, materials, "material", removed);
  const auto texture_remap = keep_marked(json, textures, "texture", removed);
  if (texture_remap_out) *texture_remap_out = texture_remap;
  const auto image_remap = keep_marked(json, images, "image", removed);
  const auto sampler_remap = keep_marked(json, samplers, "sampler", removed);
  const auto accessor_remap = keep_marked(json, accessors, "accessor", removed);
  const auto view_remap = keep_marked(json, views, "buffer view", removed);
  for_each_in(json, "nodes", [&](Json& node) {
    remap_field(node, "mesh", mesh_remap);
    for_each_node_accessor(node, [&](Json& a) { remap_value(a, accessor_remap); });
  });
  for_each_primitive(json, [&](Json& p) {
    remap_field(p, "material", material_remap);
    for_each_variant_material(p, [&](Json& material) { remap_value(material, material_remap); });
    for_each_primitive_accessor(p, [&](Json& a) { remap_value(a, accessor_remap); });
    for_each_draco_view(p, [&](Json& v) { remap_value(v, view_remap); });
  });
  remap_keys(doc.decoded.accessors, accessor_remap);
  remap_keys(doc.decoded.views, view_remap);
  for_each_other_accessor(json, [&](Json& a) { remap_value(a, accessor_remap); });
  for_each_in(json, "materials", [&](Json& m) { for_each_texture_index(m, [&](Json& t) { remap_value(t, texture_remap); }); });
  for_each_in(json, "textures", [&](Json& t) {
    for_each_texture_source(t, [&](Json& i) { remap_value(i, image_remap); });
    remap_field(t, "sampler", sampler_remap);
  });
  for_each_in(json, "accessors", [&](Json& a) {
    remap_field(a, "bufferView", view_remap);
    for_each_sparse_view(a, [&](Json& v) { remap_value(v, view_remap); });
  });
  for_each_in(json, "images", [&](Json& i) { remap_field(i, "bufferView", view_remap); });

  // One buffer with only the kept views, each 4-byte aligned (no component is larger). A view
  // beyond its buffer (tinygltf lets some through) leaves the buffers as they are.
  bool views_ok = true;
  std::size_t total = 0;
  for_each_in(json, "bufferViews", [&](Json& view) {
    const std::size_t buffer = size_in(view, "buffer", 0);
    views_ok = views_ok && buffer < doc.buffers.size() &&
               size_in(view, "byteOffset", 0) + size_in(view, "byteLength", 0) <= doc.buffers[buffer].size();
    total += size_in(view, "byteLength", 0) + 3;
  });
  if (!views_ok) return removed;
  // Every view kept, in one buffer: nothing to compact (a large scene's bytes are not copied).
  const bool all_views_kept = std::all_of(view_remap.begin(), view_remap.end(), [](int i) { return i >= 0; });
  if (all_views_kept && doc.buffers.size() == 1 && json.contains("buffers") && json["buffers"].size() == 1) {
    doc.added_buffer = -1;
    return removed;
  }
  std::vector<unsigned char> compact;
  compact.reserve(total);  // one allocation: a large scene's buffer is copied once, not regrown
  for_each_in(json, "bufferViews", [&](Json& view) {
    const auto& from = doc.buffers[size_in(view, "buffer", 0)];
    const auto begin = from.begin() + std::ptrdiff_t(size_in(view, "byteOffset", 0));
    compact.resize((compact.size() + 3) / 4 * 4, 0);
    view["buffer"] = 0;
    view["byteOffset"] = compact.size();
    compact.insert(compact.end(), begin, begin + std::ptrdiff_t(size_in(view, "byteLength", 0)));
  });
  doc.buffers.clear();
  json.erase("buffers");
  if (!compact.empty()) {
    doc.buffers.push_back(std::move(compact));
    json["buffers"] = Json::array({{{"byteLength", doc.buffers[0].size()}}});
  }
  doc.added_buffer = -1;
  return removed;
}

std::vector<int> merge_identical_images(Document& doc) {
  Json& json = doc.json;
  // Image i → the first image with the same bytes.
  std::vector<int> first(count_of(json, "images"));
  std::unordered_map<std::size_t, std::vector<std::pair<int, std::string>>> by_hash;
  for (std::size_t i = 0; i < first.size(); ++i) {
    first[i] = int(i);
    auto bytes = image_bytes(doc, i);
    if (!bytes) continue;  // unreadable: left to whoever reads it
    auto& same_hash = by_hash[std::hash<std::string>{}(*bytes)];
    const auto same = std::find_if(same_hash.begin(), same_hash.end(), [&](const auto& e) { return e.second == *bytes; });
    if (same != same_hash.end()) {
      first[i] = same->first;
    } else {
      same_hash.emplace_back(int(i), std::move(*bytes));
    }
  }
  for_each_in(json, "textures", [&](Json& t) {
    for_each_texture_source(t, [&](Json& i) {
      if (i.is_number_integer() && i.get<std::int64_t>() >= 0 && i.get<std::uint64_t>() < first.size()) i = first[i.get<std::size_t>()];
    });
  });
  // Textures that are now the same (source, sampler, extensions; a name aside) → the first of them.
  std::vector<int> texture_first(count_of(json, "textures"));
  std::map<Json, int> seen;
  for (std::size_t t = 0; t < texture_first.size(); ++t) {
    Json key = json["textures"][t];
    key.erase("name");
    texture_first[t] = seen.emplace(std::move(key), int(t)).first->second;
  }
  for_each_in(json, "materials", [&](Json& m) {
    for_each_texture_index(m, [&](Json& t) {
      if (t.is_number_integer() && t.get<std::int64_t>() >= 0 && t.get<std::uint64_t>() < texture_first.size()) {
        t = texture_first[t.get<std::size_t>()];
      }
    });
  });
  return texture_first;
}

}  // namespace matbake::gltf
