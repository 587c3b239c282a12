#include "decode.hpp"

#include <draco/compression/decode.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace matbake::gltf {
namespace {

constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kDraco = "KHR_draco_mesh_compression";
// Decoded accessors in all: a hostile count (a sparse accessor with no view, a Draco header) must
// not allocate without bound.
constexpr std::size_t kDecodedLimit = std::size_t(1) << 30;

const Json* extension_of(const Json& object, const char* name) {
  if (!object.is_object() || !object.contains("extensions") || !object["extensions"].is_object()) return nullptr;
  const auto it = object["extensions"].find(name);
  return it != object["extensions"].end() && it->is_object() ? &*it : nullptr;
}

std::string pointer(const char* array, std::size_t i) { return std::string("/") + array + "/" + std::to_string(i); }

// The bytes [offset, offset + length) of buffer `buffer`, or an empty span when they are not there.
std::span<const unsigned char> buffer_range(const Document& doc, std::size_t buffer, std::size_t offset, std::size_t length) {
  if (buffer >= doc.buffers.size() || offset > doc.buffers[buffer].size() || length > doc.buffers[buffer].size() - offset) {
    return {};
  }
  return {doc.buffers[buffer].data() + offset, length};
}

Status decode_view(Document& doc, std::size_t v, const Json& view, const Json& ext) {
  const std::string where = pointer("bufferViews", v) + "/extensions/" + kMeshopt;
  const auto bad = [&](const std::string& what) { return Error{doc.file, where + ": " + what}; };
  const std::size_t count = size_in(ext, "count", SIZE_MAX), stride = size_in(ext, "byteStride", SIZE_MAX);
  const std::size_t length = size_in(ext, "byteLength", SIZE_MAX);
  const std::string mode = ext.value("mode", ""), filter = ext.value("filter", "NONE");
  if (stride == 0 || stride > 256 || count > kDecodedLimit / std::max<std::size_t>(stride, 1)) return bad("count or byteStride out of range");
  if (count * stride != size_in(view, "byteLength", 0)) return bad("count × byteStride is not the view's byteLength");
  const auto source = buffer_range(doc, size_in(ext, "buffer", SIZE_MAX), size_in(ext, "byteOffset", 0), length);
  if (source.data() == nullptr) return bad("its compressed bytes reach beyond their buffer");
  std::vector<unsigned char> out(count * stride);
  int failed = 0;
  if (mode == "ATTRIBUTES") {
    if (stride % 4) return bad("ATTRIBUTES need a byteStride divisible by 4");
    failed = meshopt_decodeVertexBuffer(out.data(), count, stride, source.data(), source.size());
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    if (stride != 2 && stride != 4) return bad("indices need a byteStride of 2 or 4");
    if (mode == "TRIANGLES" && count % 3) return bad("TRIANGLES need a count divisible by 3");
    failed = mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), count, stride, source.data(), source.size())
                                 : meshopt_decodeIndexSequence(out.data(), count, stride, source.data(), source.size());
  } else {
    return bad("unknown mode '" + mode + "'");
  }
  if (failed) return bad("the compressed bytes are malformed (meshoptimizer's decoder refused them)");
  if (filter == "OCTAHEDRAL" && mode == "ATTRIBUTES" && (stride == 4 || stride == 8)) {
    meshopt_decodeFilterOct(out.data(), count, stride);
  } else if (filter == "QUATERNION" && mode == "ATTRIBUTES" && stride == 8) {
    meshopt_decodeFilterQuat(out.data(), count, stride);
  } else if (filter == "EXPONENTIAL" && mode == "ATTRIBUTES") {
    meshopt_decodeFilterExp(out.data(), count, stride);
  } else if (filter != "NONE") {
    return bad("filter '" + filter + "' does not fit mode " + mode + " and byteStride " + std::to_string(stride));
  }
  doc.decoded.views[v] = std::move(out);
  return success();
}

// The elements of `accessor` as its JSON declares them, tightly packed: the size it needs.
struct Layout {
  std::size_t count = 0, element = 0, component_size = 0;
  int component_type = 0;
};
Result<Layout> layout_of(const Document& doc, std::size_t a, std::size_t& budget) {
  const Json& accessor = array_in(doc.json, "accessors")[a];
  Layout out;
  out.component_type = integer_in(accessor, "componentType", 0, 0);
  out.component_size = component_size_of(out.component_type);
  out.element = components_of(accessor.value("type", "")) * out.component_size;
  out.count = size_in(accessor, "count", SIZE_MAX);
  if (out.element == 0) return Error{doc.file, pointer("accessors", a) + ": unknown type or componentType"};
  if (out.count > budget / out.element) {
    return Error{doc.file, pointer("accessors", a) + ": " + std::to_string(out.count) + " elements exceed what matbake decodes (1 GiB in all)"};
  }
  budget -= out.count * out.element;
  return out;
}

template <class T>
bool convert_attribute(const draco::PointAttribute& attribute, std::size_t points, std::size_t components, unsigned char* out) {
  T value[16];
  for (std::size_t i = 0; i < points; ++i) {
    const auto index = attribute.mapped_index(draco::PointIndex(std::uint32_t(i)));
    if (!attribute.ConvertValue<T>(index, std::int8_t(components), value)) return false;
    std::memcpy(out + i * components * sizeof(T), value, components * sizeof(T));
  }
  return true;
}

bool convert_attribute(const draco::PointAttribute& attribute, std::size_t points, const Layout& layout, unsigned char* out) {
  const std::size_t components = layout.element / layout.component_size;
  switch (layout.component_type) {
    case 5120: return convert_attribute<std::int8_t>(attribute, points, components, out);
    case 5121: return convert_attribute<std::uint8_t>(attribute, points, components, out);
    case 5122: return convert_attribute<std::int16_t>(attribute, points, components, out);
    case 5123: return convert_attribute<std::uint16_t>(attribute, points, components, out);
    case 5125: return convert_attribute<std::uint32_t>(attribute, points, components, out);
    case 5126: return convert_attribute<float>(attribute, points, components, out);
    default: return false;
  }
}

void write_index(unsigned char* out, std::size_t i, std::size_t size, std::uint32_t value) {
  if (size == 1) out[i] = static_cast<unsigned char>(value);
  if (size == 2) {
    const auto v = static_cast<std::uint16_t>(value);
    std::memcpy(out + 2 * i, &v, 2);
  }
  if (size == 4) std::memcpy(out + 4 * i, &value, 4);
}

// One Draco primitive's accessors from its compressed view.
Status decode_draco(Document& doc, const Json& primitive, const Json& ext, const std::string& where, std::size_t& budget) {
  const auto bad = [&](const std::string& what) { return Error{doc.file, where + "/extensions/" + kDraco + ": " + what}; };
  const std::size_t v = size_in(ext, "bufferView", SIZE_MAX);
  auto view = view_bytes(doc, v);
  if (!view) return bad("its buffer view cannot be read");
  draco::DecoderBuffer input;
  input.Init(reinterpret_cast<const char*>(view->data()), view->size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&input);
  if (!decoded.ok()) return bad("Draco's decoder refused it: " + decoded.status().error_msg_string());
  const draco::Mesh& mesh = *decoded.value();
  const Json& accessors = array_in(doc.json, "accessors");
  const auto accessor_of = [&](const Json& value) -> std::size_t {
    const std::size_t a = value.is_number_unsigned() ? value.get<std::size_t>() : SIZE_MAX;
    return a < accessors.size() ? a : SIZE_MAX;
  };
  static const Json no_attributes = Json::object();
  const Json& attributes = primitive.contains("attributes") && primitive["attributes"].is_object() ? primitive["attributes"] : no_attributes;
  if (!ext.contains("attributes") || !ext["attributes"].is_object()) return bad("no attributes");
  for (const auto& [name, id] : ext["attributes"].items()) {
    const std::size_t a = attributes.contains(name) ? accessor_of(attributes[name]) : SIZE_MAX;
    const draco::PointAttribute* attribute =
        id.is_number_unsigned() && id.get<std::uint64_t>() <= UINT32_MAX ? mesh.GetAttributeByUniqueId(id.get<std::uint32_t>()) : nullptr;
    if (a == SIZE_MAX || attribute == nullptr) return bad("attribute " + name + " is not in the primitive or not in the Draco data");
    if (doc.decoded.accessors.contains(a)) continue;  // shared with a primitive decoded before
    auto layout = layout_of(doc, a, budget);
    if (!layout) return layout.error();
    if (layout->count != mesh.num_points()) {
      return bad("attribute " + name + ": the accessor counts " + std::to_string(layout->count) + " vertices, the Draco data " +
                 std::to_string(mesh.num_points()));
    }
    std::vector<unsigned char> bytes(layout->count * layout->element);
    if (!convert_attribute(*attribute, layout->count, *layout, bytes.data())) return bad("attribute " + name + " cannot be converted");
    doc.decoded.accessors[a] = std::move(bytes);
  }
  if (primitive.contains("indices")) {
    const std::size_t a = accessor_of(primitive["indices"]);
    if (a == SIZE_MAX) return bad("its indices accessor does not exist");
    if (doc.decoded.accessors.contains(a)) return success();
    auto layout = layout_of(doc, a, budget);
    if (!layout) return layout.error();
    if (layout->count != std::size_t(mesh.num_faces()) * 3 || layout->element != layout->component_size ||
        layout->component_size == 0 || layout->component_type == 5126) {
      return bad("the indices accessor does not match the Draco data's " + std::to_string(mesh.num_faces()) + " triangles");
    }
    std::vector<unsigned char> bytes(layout->count * layout->element);
    const std::uint64_t largest = layout->component_size == 4 ? UINT32_MAX : (std::uint64_t(1) << (8 * layout->component_size)) - 1;
    for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f) {
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t point = mesh.face(f)[k].value();
        if (point > largest) return bad("a Draco index does not fit the indices accessor's type");
        write_index(bytes.data(), std::size_t(f.value()) * 3 + k, layout->component_size, point);
      }
    }
    doc.decoded.accessors[a] = std::move(bytes);
  }
  return success();
}

// A sparse accessor's elements: its view's (or zeros), then the substitutions.
Status apply_sparse(Document& doc, std::size_t a, std::size_t& budget) {
  const Json& accessor = array_in(doc.json, "accessors")[a];
  const std::string where = pointer("accessors", a) + "/sparse";
  const auto bad = [&](const std::string& what) { return Error{doc.file, where + ": " + what}; };
  auto layout = layout_of(doc, a, budget);
  if (!layout) return layout.error();
  std::vector<unsigned char> out(layout->count * layout->element, 0);
  if (accessor.contains("bufferView")) {
    auto dense = accessor_bytes(doc, a);
    if (!dense) return dense.error();
    for (std::size_t i = 0; i < layout->count; ++i) std::memcpy(&out[i * layout->element], dense->first + i * dense->stride, layout->element);
  }
  const Json& sparse = accessor["sparse"];
  const std::size_t count = size_in(sparse, "count", SIZE_MAX);
  if (!sparse.contains("indices") || !sparse.contains("values") || count == 0 || count > layout->count) {
    return bad("count, indices or values missing or out of range");
  }
  const Json& indices = sparse["indices"];
  const int index_type = integer_in(indices, "componentType", 0, 0);
  const std::size_t index_size = index_type == 5121 ? 1 : index_type == 5123 ? 2 : index_type == 5125 ? 4 : 0;
  if (index_size == 0) return bad("indices must be unsigned byte, short or int");
  auto index_view = view_bytes(doc, size_in(indices, "bufferView", SIZE_MAX));
  auto value_view = view_bytes(doc, size_in(sparse["values"], "bufferView", SIZE_MAX));
  if (!index_view || !value_view) return bad("its buffer views cannot be read");
  const std::size_t index_offset = size_in(indices, "byteOffset", 0), value_offset = size_in(sparse["values"], "byteOffset", 0);
  if (index_offset > index_view->size() || count > (index_view->size() - index_offset) / index_size ||
      value_offset > value_view->size() || count > (value_view->size() - value_offset) / layout->element) {
    return bad("its indices or values reach beyond their buffer views");
  }
  for (std::size_t i = 0; i < count; ++i) {
    std::uint32_t target = 0;
    std::memcpy(&target, index_view->data() + index_offset + i * index_size, index_size);  // little-endian
    if (target >= layout->count) return bad("index " + std::to_string(target) + " is beyond the accessor's " + std::to_string(layout->count) + " elements");
    std::memcpy(&out[target * layout->element], value_view->data() + value_offset + i * layout->element, layout->element);
  }
  doc.decoded.accessors[a] = std::move(out);
  return success();
}

// min and max of a decoded accessor's components, as written: Draco's quantization moves them from
// what the file declared, and the validator wants them exact.
void set_bounds(Json& accessor, const std::vector<unsigned char>& bytes) {
  const int type = integer_in(accessor, "componentType", 0, 0);
  const std::size_t size = component_size_of(type), components = components_of(accessor.value("type", ""));
  if (size == 0 || components == 0 || bytes.size() < size * components) return;
  const auto value = [&](std::size_t at) -> double {
    switch (type) {
      case 5126: { float v; std::memcpy(&v, &bytes[at], 4); return v; }
      case 5120: return double(std::int8_t(bytes[at]));
      case 5121: return bytes[at];
      case 5122: { std::int16_t v; std::memcpy(&v, &bytes[at], 2); return v; }
      case 5123: { std::uint16_t v; std::memcpy(&v, &bytes[at], 2); return v; }
      default: { std::uint32_t v; std::memcpy(&v, &bytes[at], 4); return v; }
    }
  };
  std::vector<double> low(components, INFINITY), high(components, -INFINITY);
  for (std::size_t at = 0; at + size * components <= bytes.size(); at += size * components) {
    for (std::size_t c = 0; c < components; ++c) {
      low[c] = std::min(low[c], value(at + c * size));
      high[c] = std::max(high[c], value(at + c * size));
    }
  }
  const auto as_json = [&](const std::vector<double>& v) {
    Json out = Json::array();
    for (const double x : v) type == 5126 ? out.push_back(x) : out.push_back(std::int64_t(x));
    return out;
  };
  accessor["min"] = as_json(low);
  accessor["max"] = as_json(high);
}

}  // namespace

bool is_fallback_buffer(const Json& json, std::size_t index) {
  const Json& buffers = array_in(json, "buffers");
  if (index >= buffers.size()) return false;
  const Json* ext = extension_of(buffers[index], kMeshopt);
  return ext != nullptr && ext->value("fallback", false) && !buffers[index].contains("uri");
}

Status decode_meshopt_views(Document& doc) {
  const Json& views = array_in(doc.json, "bufferViews");
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (const Json* ext = extension_of(views[v], kMeshopt)) {
      if (Status s = decode_view(doc, v, views[v], *ext); !s) return s;
    }
  }
  return success();
}

Status decode_draco_and_sparse(Document& doc) {
  std::size_t budget = kDecodedLimit;
  const Json& meshes = array_in(doc.json, "meshes");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const Json& primitives = array_in(meshes[m], "primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const Json* ext = extension_of(primitives[p], kDraco);
      if (ext == nullptr || integer_in(primitives[p], "mode", 4, -1) != 4) continue;  // Draco meshes are triangles
      const std::string where = pointer("meshes", m) + "/primitives/" + std::to_string(p);
      if (Status s = decode_draco(doc, primitives[p], *ext, where, budget); !s) return s;
    }
  }
  const Json& accessors = array_in(doc.json, "accessors");
  for (std::size_t a = 0; a < accessors.size(); ++a) {
    if (accessors[a].is_object() && accessors[a].contains("sparse") && !doc.decoded.accessors.contains(a)) {
      if (Status s = apply_sparse(doc, a, budget); !s) return s;
    }
  }
  return success();
}

bool uncompress_draco_primitive(Document& doc, std::size_t m, std::size_t p) {
  const Json primitive = doc.json["meshes"][m]["primitives"][p];  // a copy: add_view changes doc.json
  if (extension_of(primitive, kDraco) == nullptr) return false;
  const auto give_view = [&](const Json& index, int target) {
    const std::size_t a = index.get<std::size_t>();
    const auto decoded = doc.decoded.accessors.find(a);
    if (decoded == doc.decoded.accessors.end() || doc.json["accessors"][a].contains("bufferView")) return;
    const int view = add_view(doc, decoded->second, target);  // may reallocate doc.json's arrays: index anew
    Json& accessor = doc.json["accessors"][a];
    accessor["bufferView"] = view;
    if (accessor.contains("min") || accessor.contains("max")) set_bounds(accessor, decoded->second);
  };
  const Json indices = primitive.value("indices", Json()), attributes = primitive["attributes"];
  if (!indices.is_null()) give_view(indices, kElementArrayBuffer);
  for (const auto& [name, index] : attributes.items()) give_view(index, kArrayBuffer);
  Json& extensions = doc.json["meshes"][m]["primitives"][p]["extensions"];
  extensions.erase(kDraco);
  if (extensions.empty()) doc.json["meshes"][m]["primitives"][p].erase("extensions");
  bool used = false;
  for (const Json& mesh : array_in(doc.json, "meshes")) {
    for (const Json& other : array_in(mesh, "primitives")) used = used || extension_of(other, kDraco) != nullptr;
  }
  if (!used) {
    for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
      if (!doc.json.contains(list)) continue;
      Json& names = doc.json[list];
      names.erase(std::remove(names.begin(), names.end(), Json(kDraco)), names.end());
      if (names.empty()) doc.json.erase(list);
    }
  }
  return true;
}

}  // namespace matbake::gltf

namespace matbake::gltf {

std::vector<std::string> geometry_notes(const Document& doc) {
  std::vector<std::string> notes = doc.decoded.notes;  // the primitives written uncompressed
  const Json& meshes = array_in(doc.json, "meshes");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const Json& primitives = array_in(meshes[m], "primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      if (extension_of(primitives[p], kDraco) != nullptr) {
        notes.push_back("mesh " + std::to_string(m) + " primitive " + std::to_string(p) + ": " + kDraco +
                        " decoded to read, passed through compressed");
      }
    }
  }
  if (!doc.decoded.views.empty()) {
    notes.push_back(std::to_string(doc.decoded.views.size()) + " buffer views: " + kMeshopt + " decoded to read, passed through compressed");
  }
  std::size_t sparse = 0;
  for (const Json& accessor : array_in(doc.json, "accessors")) sparse += accessor.is_object() && accessor.contains("sparse");
  if (sparse) notes.push_back(std::to_string(sparse) + " sparse accessors: applied to read, passed through as written");
  return notes;
}

}  // namespace matbake::gltf
