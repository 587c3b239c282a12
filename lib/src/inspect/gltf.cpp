// `matbake inspect` of a .gltf or .glb: read as export reads it (every index checked, compressed
// geometry decoded), images measured from their headers, nothing else decoded.
#include <fcntl.h>

#include <map>
#include <set>

#include "../gltf/document.hpp"
#include "../io/unique_fd.hpp"
#include "image_facts.hpp"
#include "matbake/delivery.hpp"
#include "matbake/image.hpp"
#include "matbake/inspect.hpp"
#include "matbake/output_gate.hpp"

namespace matbake::inspect {
namespace fs = std::filesystem;
using gltf::Json;
namespace {

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kMeshopt = "EXT_meshopt_compression";

std::string component_name(int component_type) {
  switch (component_type) {
    case 5120: return "int8";
    case 5121: return "uint8";
    case 5122: return "int16";
    case 5123: return "uint16";
    case 5125: return "uint32";
    case 5126: return "float";
    default: return "unknown";
  }
}

std::size_t accessor_count(const Json& json, std::size_t accessor) {
  return gltf::size_in(gltf::array_in(json, "accessors")[accessor], "count", 0);
}

// Triangles a primitive draws: lists a third of their indices (or vertices), strips and fans all
// but two; points and lines none.
std::size_t triangles_of(const Json& json, const Json& primitive) {
  const int mode = gltf::integer_in<int>(primitive, "mode", gltf::kTriangles, -1);
  std::size_t n = 0;
  if (primitive.contains("indices")) {
    n = accessor_count(json, gltf::size_in(primitive, "indices", 0));
  } else if (primitive.contains("attributes") && primitive["attributes"].contains("POSITION")) {
    n = accessor_count(json, gltf::size_in(primitive["attributes"], "POSITION", 0));
  }
  if (mode == gltf::kTriangles) return n / 3;
  if (mode == 5 || mode == 6) return n >= 2 ? n - 2 : 0;
  return 0;
}

bool view_is_meshopt(const Json& json, const Json& accessor) {
  if (!accessor.contains("bufferView")) return false;
  const Json& view = gltf::array_in(json, "bufferViews")[gltf::size_in(accessor, "bufferView", 0)];
  return view.contains("extensions") && view["extensions"].contains(kMeshopt);
}

Json mesh_entry(const Json& json, const Json& mesh, std::size_t index) {
  std::size_t triangles = 0, vertices = 0;
  std::set<std::string> compression, quantized;
  std::map<std::string, std::string> attributes;
  for (const Json& p : gltf::array_in(mesh, "primitives")) {
    triangles += triangles_of(json, p);
    if (p.contains("extensions") && p["extensions"].contains(kDraco)) compression.insert("draco");
    if (p.contains("indices") && view_is_meshopt(json, gltf::array_in(json, "accessors")[gltf::size_in(p, "indices", 0)])) {
      compression.insert("meshopt");
    }
    if (!p.contains("attributes")) continue;
    for (const auto& [name, a] : p["attributes"].items()) {
      const Json& accessor = gltf::array_in(json, "accessors")[gltf::size_in(p["attributes"], name.c_str(), 0)];
      const int type = gltf::integer_in<int>(accessor, "componentType", 0, 0);
      std::string format = accessor.value("type", "?") + " " + component_name(type);
      if (accessor.value("normalized", false)) format += " normalized";
      attributes[name] = format;
      if (name == "POSITION") vertices += accessor_count(json, gltf::size_in(p["attributes"], "POSITION", 0));
      if (type != 5126 && (name == "POSITION" || name == "NORMAL" || name == "TANGENT" || name.rfind("TEXCOORD_", 0) == 0)) {
        quantized.insert(name);
      }
      if (view_is_meshopt(json, accessor)) compression.insert("meshopt");
    }
  }
  return {{"index", index},
          {"name", gltf::name_in(mesh, "")},
          {"primitives", gltf::array_in(mesh, "primitives").size()},
          {"triangles", triangles},
          {"vertices", vertices},
          {"attributes", attributes},
          {"compression", std::vector<std::string>(compression.begin(), compression.end())},
          {"quantized", std::vector<std::string>(quantized.begin(), quantized.end())}};
}

// Every textureInfo of a material, by its path ("pbrMetallicRoughness.baseColorTexture",
// "extensions.KHR_materials_clearcoat.clearcoatTexture").
void collect_slots(const Json& node, const std::string& path, std::vector<std::pair<std::string, const Json*>>& out) {
  if (!node.is_object()) return;
  for (const auto& [key, value] : node.items()) {
    if (!value.is_object()) continue;
    const std::string at = path.empty() ? key : path + "." + key;
    if (key.ends_with("Texture") && value.contains("index")) {
      out.push_back({at, &value});
    } else {
      collect_slots(value, at, out);
    }
  }
}

std::string workflow_of(const Json& material) {
  const Json& ext = material.contains("extensions") ? material["extensions"] : Json::object();
  if (ext.contains("KHR_materials_unlit")) return "unlit";
  if (ext.contains("KHR_materials_pbrSpecularGlossiness")) return "spec-gloss";
  return "metal-rough";
}

// Each texture's image: its core source, else KHR_texture_basisu's, else EXT_texture_webp's.
std::vector<std::pair<std::string, int>> texture_sources(const Json& texture) {
  std::vector<std::pair<std::string, int>> sources;
  if (texture.contains("source")) sources.push_back({"source", gltf::integer_in<int>(texture, "source", -1, -1)});
  if (texture.contains("extensions")) {
    for (const char* ext : {"KHR_texture_basisu", "EXT_texture_webp"}) {
      if (texture["extensions"].contains(ext)) sources.push_back({ext, gltf::integer_in<int>(texture["extensions"][ext], "source", -1, -1)});
    }
  }
  return sources;
}

struct Instances {
  std::size_t nodes = 0, placements = 0, triangles = 0;
};

Instances walk_scene(const Json& json, const Json& scene, const std::vector<std::size_t>& mesh_triangles) {
  Instances out;
  std::set<std::size_t> seen;
  std::vector<std::size_t> stack;
  for (const Json& root : gltf::array_in(scene, "nodes")) {
    if (root.is_number_unsigned()) stack.push_back(root.get<std::size_t>());
  }
  const Json& nodes = gltf::array_in(json, "nodes");
  while (!stack.empty()) {
    const std::size_t n = stack.back();
    stack.pop_back();
    if (n >= nodes.size() || !seen.insert(n).second) continue;
    ++out.nodes;
    if (nodes[n].contains("mesh")) {
      const std::size_t mesh = gltf::size_in(nodes[n], "mesh", 0);
      ++out.placements;
      if (mesh < mesh_triangles.size()) out.triangles += mesh_triangles[mesh];
    }
    for (const Json& child : gltf::array_in(nodes[n], "children")) {
      if (child.is_number_unsigned()) stack.push_back(child.get<std::size_t>());
    }
  }
  return out;
}

// Image `index` of `doc` as image_facts reads it: a file beside the glTF by its leading bytes alone
// (memory and time independent of its size), an embedded one whole.
Result<ImageHead> image_head(const gltf::Document& doc, std::size_t index) {
  const Json& image = doc.json["images"][index];
  const std::string uri = image.contains("uri") && image["uri"].is_string() ? image["uri"].get<std::string>() : "";
  if (!uri.empty() && uri.rfind("data:", 0) != 0) return read_head(doc.folder / gltf::decode_uri(uri));
  auto bytes = gltf::image_bytes(doc, index);
  if (!bytes) return bytes.error();
  return ImageHead{{bytes->begin(), bytes->end()}, bytes->size()};
}

// What tells two images' bytes apart: a file's hash read in blocks, an embedded image's of its bytes.
std::string image_hash(const gltf::Document& doc, std::size_t index, const ImageHead& head) {
  if (head.bytes.size() == head.size) return hash_bytes(head.bytes);
  const std::string uri = doc.json["images"][index]["uri"].get<std::string>();
  const UniqueFd file(::open((doc.folder / gltf::decode_uri(uri)).c_str(), O_RDONLY | O_CLOEXEC));
  return file.fd < 0 ? "unreadable " + uri : hash_file_descriptor(file.fd);
}

}  // namespace

Result<nlohmann::json> inspect_gltf(const fs::path& path) {
  auto read = gltf::read_document(path);
  if (!read) return read.error();
  const gltf::Document& doc = *read;
  const Json& json = doc.json;
  nlohmann::json out = {{"kind", "gltf"}, {"file", path.string()}};
  out["generator"] = json.contains("asset") ? json["asset"].value("generator", "") : "";
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    out[list] = nlohmann::json::array();
    for (const Json& e : gltf::array_in(json, list)) out[list].push_back(e.is_string() ? e.get<std::string>() : e.dump());
  }

  std::vector<std::size_t> mesh_triangles;
  out["meshes"] = nlohmann::json::array();
  for (const Json& mesh : gltf::array_in(json, "meshes")) {
    nlohmann::json entry = mesh_entry(json, mesh, out["meshes"].size());
    mesh_triangles.push_back(entry["triangles"].get<std::size_t>());
    out["meshes"].push_back(std::move(entry));
  }
  out["scenes"] = nlohmann::json::array();
  const std::size_t default_scene = gltf::size_in(json, "scene", 0);
  for (const Json& scene : gltf::array_in(json, "scenes")) {
    const Instances in = walk_scene(json, scene, mesh_triangles);
    out["scenes"].push_back({{"index", out["scenes"].size()},
                             {"name", gltf::name_in(scene, "")},
                             {"default", out["scenes"].size() == default_scene},
                             {"nodes", in.nodes},
                             {"mesh_placements", in.placements},
                             {"triangles", in.triangles}});
  }

  // Which material slots read each texture.
  std::map<std::size_t, std::vector<nlohmann::json>> readers;
  out["materials"] = nlohmann::json::array();
  for (const Json& material : gltf::array_in(json, "materials")) {
    const std::size_t m = out["materials"].size();
    std::vector<std::pair<std::string, const Json*>> slots;
    collect_slots(material, "", slots);
    nlohmann::json slot_list = nlohmann::json::array();
    for (const auto& [slot, info] : slots) {
      const std::size_t texture = gltf::size_in(*info, "index", 0);
      const std::string key = slot.substr(slot.rfind('.') + 1);
      slot_list.push_back({{"slot", slot}, {"texture", texture}, {"texcoord", gltf::integer_in<int>(*info, "texCoord", 0, -1)},
                           {"transform", info->contains("extensions") && (*info)["extensions"].contains("KHR_texture_transform")}});
      readers[texture].push_back({{"material", m}, {"slot", slot},
                                  {"class", name_in(delivery::kTextureClassNames, delivery::class_of_slot(key))}});
    }
    nlohmann::json extensions = nlohmann::json::array();
    if (material.contains("extensions") && material["extensions"].is_object()) {
      for (const auto& [name, value] : material["extensions"].items()) extensions.push_back(name);
    }
    out["materials"].push_back({{"index", m},
                                {"name", gltf::name_in(material, "")},
                                {"workflow", workflow_of(material)},
                                {"alpha_mode", material.value("alphaMode", "OPAQUE")},
                                {"double_sided", material.value("doubleSided", false)},
                                {"slots", slot_list},
                                {"extensions", extensions}});
  }

  // Images: measured from their bytes; the same bytes twice are a duplicate.
  std::vector<ImageFacts> facts;
  std::map<std::string, std::size_t> first_with_hash;
  std::map<std::size_t, std::vector<std::size_t>> textures_of_image;
  const Json& textures = gltf::array_in(json, "textures");
  for (std::size_t t = 0; t < textures.size(); ++t) {
    for (const auto& [key, image] : texture_sources(textures[t])) {
      if (image >= 0) textures_of_image[std::size_t(image)].push_back(t);
    }
  }
  out["images"] = nlohmann::json::array();
  std::map<std::uint64_t, std::size_t> images_of_size;  // only images of one size can be duplicates: the others are not hashed
  std::vector<ImageHead> heads;
  for (std::size_t i = 0; i < gltf::array_in(json, "images").size(); ++i) {
    auto head = image_head(doc, i);
    if (!head) return head.error();
    ++images_of_size[head->size];
    if (head->bytes.size() < head->size) head->bytes = {};  // a file's first bytes: read again below
    heads.push_back(std::move(*head));
  }
  for (std::size_t i = 0; i < heads.size(); ++i) {
    const Json& image = json["images"][i];
    auto head = heads[i].bytes.empty() ? image_head(doc, i) : Result<ImageHead>(std::move(heads[i]));
    if (!head) return head.error();
    auto measured = image_facts(head->bytes, head->size, doc.file + ": image " + std::to_string(i));
    if (!measured) return measured.error();
    facts.push_back(*measured);
    const std::string hash = images_of_size[head->size] > 1 ? image_hash(doc, i, *head) : "size " + std::to_string(head->size);
    const auto [first, fresh] = first_with_hash.try_emplace(hash, i);
    nlohmann::json entry = facts_json(*measured);
    entry["index"] = i;
    entry["name"] = gltf::name_in(image, "");
    const std::string uri = image.value("uri", "");
    entry["stored"] = !image.contains("uri") ? "buffer-view" : uri.rfind("data:", 0) == 0 ? "data-uri" : "file";
    if (entry["stored"] == "file") entry["uri"] = uri;
    entry["textures"] = textures_of_image[i];
    entry["duplicate_of"] = fresh ? nlohmann::json(nullptr) : nlohmann::json(first->second);
    out["images"].push_back(std::move(entry));
  }

  out["textures"] = nlohmann::json::array();
  for (std::size_t t = 0; t < textures.size(); ++t) {
    nlohmann::json entry = {{"index", t}, {"name", gltf::name_in(textures[t], "")}, {"used_by", readers[t]}};
    nlohmann::json sources = nlohmann::json::array();
    for (const auto& [key, image] : texture_sources(textures[t])) {
      if (image < 0 || std::size_t(image) >= facts.size()) continue;
      nlohmann::json s = facts_json(facts[std::size_t(image)]);
      s["via"] = key;
      s["image"] = image;
      sources.push_back(std::move(s));
    }
    entry["sources"] = sources;
    out["textures"].push_back(std::move(entry));
  }
  out["totals"] = totals_json(out);
  return out;
}

}  // namespace matbake::inspect
