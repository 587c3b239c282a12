#include "geometry.hpp"

#include <meshoptimizer.h>

#include <glm/common.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include "../gltf/decode.hpp"
#include "../gltf/prune.hpp"
#include "../gltf/texture_transform.hpp"
#include "join.hpp"

namespace matbake::delivery {
namespace {

using gltf::array_in;
using gltf::Json;

using gltf::kTriangles;
constexpr const char* kQuantization = "KHR_mesh_quantization";
constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kTransform = "KHR_texture_transform";
constexpr std::uint32_t kUnused = ~0u;

std::string primitive_pointer(std::size_t m, std::size_t p) {
  return "/meshes/" + std::to_string(m) + "/primitives/" + std::to_string(p);
}

// Texture coordinate set n over every primitive that holds it: quantized only when each of them is
// rewritten (one range, undone by one transform in every material that reads the set).
struct UvSet {
  glm::dvec2 lo{std::numeric_limits<double>::max()}, hi{std::numeric_limits<double>::lowest()};
  bool quantize = true;
  glm::dvec2 range() const { return glm::max(hi - lo, glm::dvec2(0.0)); }
};

// A mesh's positions: on one uniform grid (uniform, so that the dequantizing scale bends no normal)
// when every primitive is rewritten and no node skins or instances it.
struct MeshGrid {
  glm::dvec3 lo{std::numeric_limits<double>::max()}, hi{std::numeric_limits<double>::lowest()};
  bool quantize = true;
  double step(int bits) const {
    const double side = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 0.0});
    return side > 0 ? side / double((1 << bits) - 1) : 1.0;
  }
};

struct Plan {
  std::vector<std::pair<std::size_t, std::size_t>> rewritten;  // (mesh, primitive)
  std::vector<std::string> kept;                               // primitives kept as read, why
  std::vector<MeshGrid> meshes;
  std::map<int, UvSet> uv;  // by set
};

int texcoord_set(const std::string& attribute) {
  if (!attribute.starts_with("TEXCOORD_")) return -1;
  const std::string digits = attribute.substr(9);
  if (digits.empty() || digits.size() > 4 || !std::all_of(digits.begin(), digits.end(), ::isdigit)) return -1;
  return std::stoi(digits);
}

// An attribute's kind: its name without the set number ("COLOR_1": "COLOR"; "_AO" stays).
std::string attribute_kind(const std::string& name) {
  const std::size_t underscore = name.rfind('_');
  if (underscore == std::string::npos || underscore + 1 == name.size()) return name;
  const bool numbered = std::all_of(name.begin() + std::ptrdiff_t(underscore) + 1, name.end(), ::isdigit);
  return numbered ? name.substr(0, underscore) : name;
}

// Element i's components as floats, as a runtime reads them.
std::array<float, 4> element(const gltf::AccessorBytes& a, std::size_t i) {
  std::array<float, 4> v{0, 0, 0, 1};
  const unsigned char* p = a.first + i * a.stride;
  for (std::size_t c = 0; c < std::min<std::size_t>(a.components, 4); ++c) {
    v[c] = gltf::component_value(p + c * a.component_size, a.component_type, a.normalized);
  }
  return v;
}

// Why a primitive is kept as read, or nothing when it is rewritten.
std::optional<std::string> kept_because(const gltf::Document& doc, const Json& primitive) {
  if (gltf::integer_in(primitive, "mode", kTriangles, -1) != kTriangles) return "not a triangle list";
  if (primitive.contains("targets")) return "morph targets";
  const auto attributes = primitive.find("attributes");
  if (attributes == primitive.end() || !attributes->is_object() || !attributes->contains("POSITION")) return "no POSITION";
  for (const auto& [name, index] : attributes->items()) {
    const std::size_t a = index.is_number_integer() && index.get<std::int64_t>() >= 0 ? index.get<std::size_t>() : SIZE_MAX;
    const Json& accessors = array_in(doc.json, "accessors");
    if (a >= accessors.size() || !accessors[a].is_object()) return "attribute " + name + " names no accessor";
    const std::size_t components = gltf::components_of(accessors[a].value("type", ""));
    if (components == 0 || components > 4) return "attribute " + name + " is not a scalar or vector";
  }
  return std::nullopt;
}

Result<Plan> plan_geometry(const gltf::Document& doc) {
  Plan plan;
  const Json& meshes = array_in(doc.json, "meshes");
  plan.meshes.resize(meshes.size());
  for (const Json& node : array_in(doc.json, "nodes")) {
    const std::size_t m = gltf::size_in(node, "mesh", SIZE_MAX);
    // Skinned or instanced: the node's transform does not come right after the vertices'. Children
    // not a list: the dequantizing child cannot be added.
    const bool placed_otherwise = node.contains("skin") || (node.contains("extensions") && node["extensions"].contains("EXT_mesh_gpu_instancing")) ||
                                  (node.contains("children") && !node["children"].is_array());
    if (m < meshes.size() && placed_otherwise) plan.meshes[m].quantize = false;
  }
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const Json& primitives = array_in(meshes[m], "primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const Json& primitive = primitives[p];
      if (const auto why = kept_because(doc, primitive)) {
        plan.kept.push_back(primitive_pointer(m, p) + ": " + *why);
        plan.meshes[m].quantize = false;
        if (primitive.contains("attributes") && primitive["attributes"].is_object()) {
          for (const auto& [name, index] : primitive["attributes"].items()) {
            if (const int set = texcoord_set(name); set >= 0) plan.uv[set].quantize = false;
          }
        }
        continue;
      }
      plan.rewritten.emplace_back(m, p);
      for (const auto& [name, index] : primitive["attributes"].items()) {
        const int set = texcoord_set(name);
        if (name != "POSITION" && set < 0) continue;
        auto a = gltf::accessor_bytes(doc, index.get<std::size_t>());
        if (!a) return a.error();
        if (a->components != (set < 0 ? 3u : 2u)) {  // not what glTF says it is: written as read, so no grid
          (set < 0 ? plan.meshes[m].quantize : plan.uv[set].quantize) = false;
          continue;
        }
        for (std::size_t i = 0; i < a->count; ++i) {
          const auto v = element(*a, i);
          if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {  // as the scene reader refuses it
            return Error{doc.file, primitive_pointer(m, p) + ": " + name + " element " + std::to_string(i) + " is not finite"};
          }
          if (name == "POSITION") {
            plan.meshes[m].lo = glm::min(plan.meshes[m].lo, glm::dvec3(v[0], v[1], v[2]));
            plan.meshes[m].hi = glm::max(plan.meshes[m].hi, glm::dvec3(v[0], v[1], v[2]));
          } else {
            plan.uv[set].lo = glm::min(plan.uv[set].lo, glm::dvec2(v[0], v[1]));
            plan.uv[set].hi = glm::max(plan.uv[set].hi, glm::dvec2(v[0], v[1]));
          }
        }
      }
    }
  }
  // A range a double cannot hold (±1e308 apart) has no grid either.
  for (MeshGrid& g : plan.meshes) g.quantize = g.quantize && g.lo.x <= g.hi.x && std::isfinite(g.step(16));
  for (auto& [set, uv] : plan.uv) uv.quantize = uv.quantize && uv.lo.x <= uv.hi.x && std::isfinite(uv.range().x + uv.range().y);
  return plan;
}

// One accessor's elements as they will be written: tightly packed at a stride padded to 4 bytes
// (what vertex buffers and meshopt's ATTRIBUTES need).
struct Stream {
  std::vector<unsigned char> bytes;
  std::size_t stride = 0;
  Json accessor;  // componentType, count, type, normalized; min and max for POSITION
};

Stream make_stream(std::size_t count, std::size_t components, int component_type, bool normalized) {
  static const char* const kTypes[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
  Stream s;
  s.stride = (components * gltf::component_size_of(component_type) + 3) / 4 * 4;
  s.bytes.assign(count * s.stride, 0);
  s.accessor = {{"componentType", component_type}, {"count", count}, {"type", kTypes[components]}};
  if (normalized) s.accessor["normalized"] = true;
  return s;
}

template <class T>
void put(Stream& s, std::size_t i, std::size_t c, T value) {
  std::memcpy(&s.bytes[i * s.stride + c * sizeof(T)], &value, sizeof value);
}

template <class T>
T quantized(double v, double max) {
  return T(std::clamp(std::lround(v), 0l, long(max)));
}

void set_min_max(Stream& s) {
  const int type = s.accessor["componentType"].get<int>();
  const std::size_t components = gltf::components_of(s.accessor["type"].get<std::string>());
  const std::size_t size = gltf::component_size_of(type), count = s.accessor["count"].get<std::size_t>();
  std::vector<double> lo(components, std::numeric_limits<double>::max()), hi(components, std::numeric_limits<double>::lowest());
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t c = 0; c < components; ++c) {
      const double v = gltf::component_value(&s.bytes[i * s.stride + c * size], type, false);  // stored values
      lo[c] = std::min(lo[c], v);
      hi[c] = std::max(hi[c], v);
    }
  }
  s.accessor["min"] = lo;
  s.accessor["max"] = hi;
}

// How one attribute is written: as read (its bytes), or quantized.
enum class Encoding { as_read, position, normal, tangent, texcoord, colour };

struct AttributeJob {
  std::string name;
  gltf::AccessorBytes in;
  Encoding encoding = Encoding::as_read;
};

Encoding encoding_of(const AttributeJob& a, const Plan& plan, std::size_t mesh, const GeometryOptions& options) {
  if (!options.quantize) return Encoding::as_read;
  const std::size_t n = a.in.components;
  if (a.name == "POSITION") return n == 3 && plan.meshes[mesh].quantize ? Encoding::position : Encoding::as_read;
  if (a.name == "NORMAL") return n == 3 ? Encoding::normal : Encoding::as_read;
  if (a.name == "TANGENT") return n == 4 ? Encoding::tangent : Encoding::as_read;
  if (const int set = texcoord_set(a.name); set >= 0) return n == 2 && plan.uv.at(set).quantize ? Encoding::texcoord : Encoding::as_read;
  if (a.name.starts_with("COLOR_") && (n == 3 || n == 4)) {
    if (a.in.component_type == gltf::kUnsignedShort && a.in.normalized) return Encoding::colour;
    if (a.in.component_type != gltf::kFloat) return Encoding::as_read;
    for (std::size_t i = 0; i < a.in.count; ++i) {
      const auto v = element(a.in, i);
      for (std::size_t c = 0; c < n; ++c) {
        if (!(v[c] >= 0 && v[c] <= 1)) return Encoding::as_read;  // HDR or NaN: kept as float
      }
    }
    return Encoding::colour;
  }
  return Encoding::as_read;
}

// Attribute `a` with its vertices moved as `remap` says (old index → new; kUnused: dropped).
Stream encode_attribute(const AttributeJob& a, const std::vector<std::uint32_t>& remap, std::size_t vertices, const Plan& plan,
                        std::size_t mesh, const GeometryOptions& options) {
  const auto each = [&](Stream s, auto&& write) {
    for (std::size_t i = 0; i < a.in.count; ++i) {
      if (remap[i] != kUnused) write(s, remap[i], i);
    }
    return s;
  };
  switch (a.encoding) {
    case Encoding::position: {
      const MeshGrid& g = plan.meshes[mesh];
      const double step = g.step(options.position_bits), max = double((1 << options.position_bits) - 1);
      Stream s = each(make_stream(vertices, 3, gltf::kUnsignedShort, false), [&](Stream& out, std::size_t to, std::size_t from) {
        const auto v = element(a.in, from);
        for (int c = 0; c < 3; ++c) put(out, to, c, quantized<std::uint16_t>((v[c] - g.lo[c]) / step, max));
      });
      set_min_max(s);
      return s;
    }
    case Encoding::normal:
    case Encoding::tangent: {
      const std::size_t n = a.encoding == Encoding::normal ? 3 : 4;
      return each(make_stream(vertices, n, gltf::kByte, true), [&](Stream& out, std::size_t to, std::size_t from) {
        const auto v = element(a.in, from);
        const double length = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
        for (int c = 0; c < 3; ++c) put(out, to, c, std::int8_t(length > 0 ? std::lround(v[c] / length * 127) : 0));
        if (n == 4) put(out, to, 3, std::int8_t(v[3] < 0 ? -127 : 127));
      });
    }
    case Encoding::texcoord: {
      const UvSet& uv = plan.uv.at(texcoord_set(a.name));
      const double max = double((1 << options.texcoord_bits) - 1);
      const glm::dvec2 range = glm::max(uv.range(), glm::dvec2(std::numeric_limits<double>::min()));
      return each(make_stream(vertices, 2, gltf::kUnsignedShort, true), [&](Stream& out, std::size_t to, std::size_t from) {
        const auto v = element(a.in, from);
        for (int c = 0; c < 2; ++c) put(out, to, c, quantized<std::uint16_t>((v[c] - uv.lo[c]) / range[c] * max, max));
      });
    }
    case Encoding::colour:
      return each(make_stream(vertices, a.in.components, gltf::kUnsignedByte, true), [&](Stream& out, std::size_t to, std::size_t from) {
        const auto v = element(a.in, from);
        for (std::size_t c = 0; c < a.in.components; ++c) put(out, to, c, quantized<std::uint8_t>(v[c] * 255.0, 255));
      });
    case Encoding::as_read: break;
  }
  Stream s = each(make_stream(vertices, a.in.components, a.in.component_type, a.in.normalized), [&](Stream& out, std::size_t to, std::size_t from) {
    std::memcpy(&out.bytes[to * out.stride], a.in.first + from * a.in.stride, a.in.components * a.in.component_size);
  });
  if (a.name == "POSITION") set_min_max(s);
  return s;
}

// The accessors this pass writes, each stored once, then laid out as gltfpack does: one buffer view
// per kind of stream (position, normal, TEXCOORD, ..., 16- or 32-bit indices), the accessors one
// after another in it, so that meshopt compresses long streams rather than many short ones.
struct Writer {
  gltf::Document& doc;
  struct Pending {
    Stream stream;
    std::string group;  // its view: target, kind and stride
    int accessor = -1;
  };
  std::vector<Pending> pending;
  std::unordered_map<std::size_t, std::vector<std::size_t>> by_hash;  // into pending
  std::size_t bytes = 0;                                              // of the views written
  std::map<std::string, int> dropped;                                 // unread attributes, by name

  // `s` as an accessor of the kind `kind` ("TEXCOORD", "indices"): its index, the same for the same stream.
  int accessor(Stream s, const std::string& kind) {
    const std::string json = s.accessor.dump();
    const std::string_view bytes_view(reinterpret_cast<const char*>(s.bytes.data()), s.bytes.size());
    auto& same_hash = by_hash[std::hash<std::string_view>{}(bytes_view) ^ std::hash<std::string>{}(json)];
    for (std::size_t k : same_hash) {
      if (pending[k].stream.bytes == s.bytes && pending[k].stream.accessor == s.accessor) return pending[k].accessor;
    }
    const int index = int(array_in(doc.json, "accessors").size());
    doc.json["accessors"].push_back(s.accessor);
    same_hash.push_back(pending.size());
    std::string group = kind + "/" + std::to_string(s.stride);
    pending.push_back({std::move(s), std::move(group), index});
    return index;
  }

  // Every pending accessor placed in its group's view.
  void write_views() {
    std::map<std::string, std::vector<const Pending*>> groups;
    for (const Pending& p : pending) groups[p.group].push_back(&p);
    for (const auto& [group, members] : groups) {
      const bool indices = group.starts_with("indices");
      const std::size_t stride = members.front()->stream.stride;
      std::vector<unsigned char> joined;
      for (const Pending* p : members) {
        doc.json["accessors"][std::size_t(p->accessor)]["byteOffset"] = joined.size();
        joined.insert(joined.end(), p->stream.bytes.begin(), p->stream.bytes.end());
      }
      const int view = gltf::add_view(doc, joined, indices ? gltf::kElementArrayBuffer : gltf::kArrayBuffer);
      if (!indices) doc.json["bufferViews"][std::size_t(view)]["byteStride"] = stride;
      for (const Pending* p : members) {
        Json& accessor = doc.json["accessors"][std::size_t(p->accessor)];
        accessor["bufferView"] = view;
        if (accessor["byteOffset"] == 0) accessor.erase("byteOffset");
      }
      bytes += joined.size();
    }
    pending.clear();
  }
};

// The primitive's triangles (its indices, or its vertices in order), incomplete triangles dropped.
Result<std::vector<std::uint32_t>> triangle_indices(const gltf::Document& doc, const Json& primitive, std::size_t vertices,
                                                    const std::string& where) {
  std::vector<std::uint32_t> out;
  if (!primitive.contains("indices")) {
    out.resize(vertices / 3 * 3);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = std::uint32_t(i);
    return out;
  }
  auto a = gltf::accessor_bytes(doc, gltf::size_in(primitive, "indices", SIZE_MAX));
  if (!a) return a.error();
  if (a->components != 1 || (a->component_type != gltf::kUnsignedByte && a->component_type != gltf::kUnsignedShort &&
                              a->component_type != gltf::kUnsignedInt)) {
    return Error{doc.file, where + ": indices are not unsigned byte, short or int scalars"};
  }
  out.resize(a->count / 3 * 3);
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = gltf::index_value(a->first + i * a->stride, a->component_type);
    if (out[i] >= vertices) {
      return Error{doc.file, where + ": index " + std::to_string(out[i]) + " is beyond the " + std::to_string(vertices) + " vertices"};
    }
  }
  return out;
}

Stream index_stream(const std::vector<std::uint32_t>& indices, std::size_t vertices) {
  // WebGL 2 restarts primitives at the largest index of the type: 16 bits only below it.
  const bool short_indices = vertices < 0xffff;
  Stream s = make_stream(indices.size(), 1, short_indices ? gltf::kUnsignedShort : gltf::kUnsignedInt, false);
  s.stride = short_indices ? 2 : 4;  // indices are tightly packed
  s.bytes.resize(indices.size() * s.stride);
  for (std::size_t i = 0; i < indices.size(); ++i) {
    short_indices ? put(s, i, 0, std::uint16_t(indices[i])) : put(s, i, 0, indices[i]);
  }
  return s;
}

// The attributes no material of the primitive reads (its own and its KHR_materials_variants ones):
// a TEXCOORD_n no texture samples, a TANGENT where no normal map or anisotropy needs one. gltfpack
// drops them too; a runtime never fetches them.
std::set<std::string> unread_attributes(gltf::Document& doc, const Json& primitive) {
  std::vector<std::size_t> materials;
  if (const std::size_t m = gltf::size_in(primitive, "material", SIZE_MAX); m != SIZE_MAX) materials.push_back(m);
  if (primitive.contains("extensions") && primitive["extensions"].contains("KHR_materials_variants")) {
    for (const Json& mapping : array_in(primitive["extensions"]["KHR_materials_variants"], "mappings")) {
      materials.push_back(gltf::size_in(mapping, "material", SIZE_MAX));
    }
  }
  std::set<int> sets;
  bool tangents = false;
  for (std::size_t m : materials) {
    if (m >= array_in(doc.json, "materials").size()) return {};  // unknown: nothing is dropped
    Json& material = doc.json["materials"][m];
    tangents = tangents || (material.contains("extensions") && material["extensions"].contains("KHR_materials_anisotropy"));
    bool readable = true;
    gltf::for_each_texture_info(material, [&](Json& info) {
      auto t = gltf::uv_transform_of(info, doc.file, "");
      readable = readable && bool(t);
      if (t) sets.insert(t->texcoord >= 0 ? t->texcoord : gltf::integer_in(info, "texCoord", 0, -1));
    });
    if (!readable) return {};
    const std::string text = material.dump();
    tangents = tangents || text.find("ormalTexture\"") != std::string::npos;  // normalTexture, clearcoatNormalTexture
  }
  std::set<std::string> unread;
  for (const auto& [name, index] : primitive["attributes"].items()) {
    const int set = texcoord_set(name);
    if ((set >= 0 && !sets.contains(set)) || (name == "TANGENT" && !tangents)) unread.insert(name);
  }
  return unread;
}

// Mesh m's primitive p written anew: reordered, its attributes encoded as planned.
Status rewrite_primitive(Writer& writer, const Plan& plan, std::size_t m, std::size_t p, const GeometryOptions& options) {
  gltf::Document& doc = writer.doc;
  gltf::uncompress_draco_primitive(doc, m, p);  // its accessors then read their decoded elements
  const std::string where = primitive_pointer(m, p);
  const Json primitive = doc.json["meshes"][m]["primitives"][p];
  const std::set<std::string> unread = unread_attributes(doc, primitive);
  std::vector<AttributeJob> attributes;
  for (const auto& [name, index] : primitive["attributes"].items()) {
    if (unread.contains(name) && name != "POSITION") continue;
    auto a = gltf::accessor_bytes(doc, index.get<std::size_t>());
    if (!a) return a.error();
    attributes.push_back({name, *a});
  }
  const std::size_t vertices = std::find_if(attributes.begin(), attributes.end(), [](auto& a) { return a.name == "POSITION"; })->in.count;
  for (AttributeJob& a : attributes) {
    if (a.in.count != vertices) {
      return Error{doc.file, where + ": attribute " + a.name + " has " + std::to_string(a.in.count) + " elements, POSITION " + std::to_string(vertices)};
    }
    a.encoding = encoding_of(a, plan, m, options);
  }
  auto indices = triangle_indices(doc, primitive, vertices, where);
  if (!indices) return indices.error();
  meshopt_optimizeVertexCache(indices->data(), indices->data(), indices->size(), vertices);
  std::vector<std::uint32_t> remap(vertices);
  const std::size_t used = meshopt_optimizeVertexFetchRemap(remap.data(), indices->data(), indices->size(), vertices);
  meshopt_remapIndexBuffer(indices->data(), indices->data(), indices->size(), remap.data());

  // Only accessors are made here; their views are written once every primitive is (Writer::write_views),
  // so no attribute being read moves.
  Json written = primitive;
  for (const std::string& name : unread) {
    written["attributes"].erase(name);
    ++writer.dropped[name];
  }
  for (const AttributeJob& a : attributes) {
    written["attributes"][a.name] = writer.accessor(encode_attribute(a, remap, used, plan, m, options), attribute_kind(a.name));
  }
  written["indices"] = writer.accessor(index_stream(*indices, used), "indices");
  doc.json["meshes"][m]["primitives"][p] = std::move(written);
  return success();
}

void add_extension(Json& json, const char* name, bool required) {
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    if (list[9] == 'R' && !required) continue;
    Json& names = json[list];
    if (!names.is_array()) names = Json::array();  // a malformed list (the validator's error) replaced
    if (std::find(names.begin(), names.end(), Json(name)) == names.end()) names.push_back(name);
  }
}

// Each mesh on a quantized grid is placed by a child node of each node that placed it, whose
// translation and scale undo the grid (KHR_mesh_quantization's way: the node's own transform, its
// children and what animates it stay as they were).
void place_on_grids(gltf::Document& doc, const Plan& plan, const GeometryOptions& options) {
  const std::size_t nodes = array_in(doc.json, "nodes").size();
  for (std::size_t n = 0; n < nodes; ++n) {
    const std::size_t m = gltf::size_in(doc.json["nodes"][n], "mesh", SIZE_MAX);
    if (m >= plan.meshes.size() || !plan.meshes[m].quantize) continue;
    const MeshGrid& g = plan.meshes[m];
    // As float32, which runtimes apply them in (and the file's text is then short).
    const float step = float(g.step(options.position_bits));
    const glm::vec3 lo(g.lo);
    doc.json["nodes"].push_back({{"mesh", m}, {"translation", {lo.x, lo.y, lo.z}}, {"scale", {step, step, step}}});
    Json& node = doc.json["nodes"][n];
    node.erase("mesh");
    node["children"].push_back(doc.json["nodes"].size() - 1);
  }
}

// Every textureInfo reading a quantized set gets the set's dequantization before its own transform:
// T(lo + s ⊙ q) = T(lo) + R (scale ⊙ s ⊙ q), so offset' = T(lo), scale' = scale ⊙ s, rotation kept.
Status undo_uv_grids(gltf::Document& doc, const Plan& plan, const GeometryOptions& options, bool& added) {
  Json& materials = doc.json["materials"];
  if (!materials.is_array()) return success();
  for (std::size_t m = 0; m < materials.size(); ++m) {
    Status status = success();
    gltf::for_each_texture_info(materials[m], [&](Json& info) {
      if (!status) return;
      auto t = gltf::uv_transform_of(info, doc.file, "/materials/" + std::to_string(m));
      if (!t) {
        status = t.error();
        return;
      }
      const int set = t->texcoord >= 0 ? t->texcoord : gltf::integer_in(info, "texCoord", 0, -1);
      const auto uv = plan.uv.find(set);
      if (uv == plan.uv.end() || !uv->second.quantize) return;
      if (info.contains("extensions") && !info["extensions"].is_object()) {
        status = Error{doc.file, "/materials/" + std::to_string(m) + ": a texture's extensions are not an object"};
        return;
      }
      const glm::dvec2 s = uv->second.range() * (65535.0 / double((1 << options.texcoord_bits) - 1));
      const glm::dvec2 offset = t->apply(uv->second.lo), scale = t->scale * s;
      Json& ext = info["extensions"][kTransform];
      ext["offset"] = {float(offset.x), float(offset.y)};  // float32, as runtimes apply them
      ext["scale"] = {float(scale.x), float(scale.y)};
      added = true;
    });
    if (!status) return status;
  }
  return success();
}

// A view's bytes meshopt-encoded, and the extension's fields but for where they lie.
struct Encoded {
  std::vector<unsigned char> bytes;
  Json extension;
};

Encoded encode_vertices(std::span<const unsigned char> plain, std::size_t stride) {
  const std::size_t count = plain.size() / stride;
  Encoded e{std::vector<unsigned char>(meshopt_encodeVertexBufferBound(count, stride)),
            {{"byteStride", stride}, {"count", count}, {"mode", "ATTRIBUTES"}}};
  e.bytes.resize(meshopt_encodeVertexBuffer(e.bytes.data(), e.bytes.size(), plain.data(), count, stride));
  return e;
}

Encoded encode_triangles(std::span<const unsigned char> plain, std::size_t index_size) {
  const std::size_t count = plain.size() / index_size;
  std::vector<std::uint32_t> indices(count);
  const int type = index_size == 2 ? gltf::kUnsignedShort : gltf::kUnsignedInt;
  for (std::size_t k = 0; k < count; ++k) indices[k] = gltf::index_value(plain.data() + k * index_size, type);
  const std::size_t vertices = indices.empty() ? 0 : std::size_t(*std::max_element(indices.begin(), indices.end())) + 1;
  // Version 1 of the index codec (EXT_meshopt_compression's decoders read both; libmeshoptimizer 0.18
  // writes 0 unless told): on OrientationTest's 1 048 indices 1 522 → 550 bytes, as gltfpack writes.
  static const bool version_set = (meshopt_encodeIndexVersion(1), true);
  (void)version_set;
  Encoded e{std::vector<unsigned char>(meshopt_encodeIndexBufferBound(count, vertices)),
            {{"byteStride", index_size}, {"count", count}, {"mode", "TRIANGLES"}}};
  e.bytes.resize(meshopt_encodeIndexBuffer(e.bytes.data(), e.bytes.size(), indices.data(), count));
  return e;
}

// The views of the rewritten primitives, compressed: their meshopt bytes in buffer 0, the views
// themselves in a fallback buffer with no bytes. Every other view is copied into buffer 0 (a view
// compressed before keeps its compression). Runs after pruning, so no view is left unused.
Result<std::size_t> compress_views(gltf::Document& doc, const Plan& plan) {
  Json& json = doc.json;
  std::map<std::size_t, std::size_t> attribute_views, index_views;  // view → its elements' bytes
  const auto view_of = [&](const Json& a) { return json["accessors"][a.get<std::size_t>()]["bufferView"].get<std::size_t>(); };
  for (const auto& [m, p] : plan.rewritten) {
    const Json& primitive = json["meshes"][m]["primitives"][p];
    for (const auto& [name, a] : primitive["attributes"].items()) {
      attribute_views[view_of(a)] = json["bufferViews"][view_of(a)]["byteStride"].get<std::size_t>();
    }
    const Json& indices = json["accessors"][primitive["indices"].get<std::size_t>()];
    index_views[view_of(primitive["indices"])] = gltf::component_size_of(indices.value("componentType", 0));
  }
  std::vector<unsigned char> main;
  std::size_t fallback = 0, written = 0;
  const auto append = [&](std::span<const unsigned char> bytes) {
    main.resize((main.size() + 3) / 4 * 4, 0);
    const std::size_t at = main.size();
    main.insert(main.end(), bytes.begin(), bytes.end());
    return at;
  };
  // The view's bytes now lie compressed at `at` in buffer 0; the view itself in the fallback buffer.
  const auto into_fallback = [&](Json& view, std::size_t at, std::size_t length, Json ext) {
    ext["buffer"] = 0;
    ext["byteOffset"] = at;
    ext["byteLength"] = length;
    view["extensions"][kMeshopt] = std::move(ext);
    fallback = (fallback + 3) / 4 * 4;
    view["buffer"] = 1;
    view["byteOffset"] = fallback;
    fallback += gltf::size_in(view, "byteLength", 0);
  };
  for (std::size_t v = 0; v < json["bufferViews"].size(); ++v) {
    Json& view = json["bufferViews"][v];
    auto plain = gltf::view_bytes(doc, v);
    if (!plain) return plain.error();
    std::optional<Encoded> encoded;
    if (const auto a = attribute_views.find(v); a != attribute_views.end()) encoded = encode_vertices(*plain, a->second);
    if (const auto i = index_views.find(v); i != index_views.end()) encoded = encode_triangles(*plain, i->second);
    if (encoded && encoded->bytes.size() < plain->size()) {  // tiny streams grow: they stay plain
      written += encoded->bytes.size();
      into_fallback(view, append(encoded->bytes), encoded->bytes.size(), std::move(encoded->extension));
      doc.decoded.views[v].assign(plain->begin(), plain->end());
    } else if (view.contains("extensions") && view["extensions"].contains(kMeshopt)) {  // compressed as read
      Json ext = view["extensions"][kMeshopt];
      const std::size_t b = gltf::size_in(ext, "buffer", SIZE_MAX), at = gltf::size_in(ext, "byteOffset", 0), length = gltf::size_in(ext, "byteLength", 0);
      if (b >= doc.buffers.size() || at > doc.buffers[b].size() || length > doc.buffers[b].size() - at) {
        return Error{doc.file, "/bufferViews/" + std::to_string(v) + ": its compressed bytes reach beyond their buffer"};
      }
      into_fallback(view, append({doc.buffers[b].data() + at, length}), length, std::move(ext));
    } else {
      written += encoded ? plain->size() : 0;
      view["buffer"] = 0;
      view["byteOffset"] = append(*plain);
    }
  }
  json["buffers"] = Json::array({{{"byteLength", main.size()}}});
  doc.buffers.clear();
  doc.buffers.push_back(std::move(main));
  if (fallback) {
    json["buffers"].push_back({{"byteLength", fallback}, {"extensions", {{kMeshopt, {{"fallback", true}}}}}});
    doc.buffers.emplace_back();
  }
  doc.added_buffer = -1;
  return written;
}

}  // namespace

double position_error_bound(double longest_side, int bits) { return 0.5 * longest_side / double((1 << bits) - 1); }
double texcoord_error_bound(double range, int bits) { return 0.5 * range / double((1 << bits) - 1); }

Result<std::vector<std::string>> deliver_geometry(gltf::Document& doc, const GeometryOptions& options) {
  std::vector<std::string> notes;
  if (!options.any()) return notes;
  if (options.join) {
    auto joined = join_meshes(doc);
    if (!joined) return joined.error();
    notes = std::move(*joined);
  }
  // Only what the default scene reaches (export has pruned already): the pruning after the rewrite
  // then removes accessors and views only, and the primitives planned keep their indices.
  (void)gltf::prune_unreachable(doc);
  auto plan = plan_geometry(doc);
  if (!plan) return plan.error();
  Writer writer{doc, {}, {}};
  for (const auto& [m, p] : plan->rewritten) {
    if (Status s = rewrite_primitive(writer, *plan, m, p, options); !s) return s.error();
  }
  writer.write_views();
  bool transformed = false;
  if (options.quantize) {
    place_on_grids(doc, *plan, options);
    if (Status s = undo_uv_grids(doc, *plan, options, transformed); !s) return s.error();
    add_extension(doc.json, kQuantization, true);
    if (transformed) add_extension(doc.json, kTransform, true);
  }
  (void)gltf::prune_unreachable(doc);  // the accessors and views the rewritten primitives no longer read
  notes.push_back(std::to_string(plan->rewritten.size()) + " triangle lists reordered for the vertex cache and fetch (meshoptimizer): " +
                  std::to_string(writer.bytes) + " bytes of vertices and indices");
  if (options.quantize) {
    const auto quantized_meshes = std::count_if(plan->meshes.begin(), plan->meshes.end(), [](const MeshGrid& g) { return g.quantize; });
    notes.push_back("quantized (" + std::string(kQuantization) + "): positions of " + std::to_string(quantized_meshes) + " of " +
                    std::to_string(plan->meshes.size()) + " meshes at " + std::to_string(options.position_bits) +
                    " bits, normals and tangents 8 bits, colours 8 bits, texture coordinates " + std::to_string(options.texcoord_bits) + " bits");
  }
  if (options.compression == MeshCompression::meshopt && !plan->rewritten.empty()) {
    auto compressed = compress_views(doc, *plan);
    if (!compressed) return compressed.error();
    if (gltf::is_fallback_buffer(doc.json, doc.buffers.size() - 1)) add_extension(doc.json, kMeshopt, true);  // any compressed
    notes.push_back(std::string(kMeshopt) + ": " + std::to_string(writer.bytes) + " → " + std::to_string(*compressed) + " bytes");
  }
  for (const auto& [name, count] : writer.dropped) {
    notes.push_back(name + " dropped from " + std::to_string(count) + " primitives: no material reads it");
  }
  for (const std::string& k : plan->kept) notes.push_back(k + ": kept as read");
  return notes;
}

}  // namespace matbake::delivery
