#pragma once
// A glTF file as its JSON plus the bytes of its buffers, for writers that change a few things and
// keep the rest as it was (node, mesh and material order, names, extras, extensions; key order).
// tinygltf reads and checks the file (GLB chunks, data: URIs, buffer sizes); the JSON is kept as
// written rather than rebuilt from tinygltf's model, which would drop what it does not know.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <type_traits>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "matbake/result.hpp"

namespace matbake::gltf {

using Json = nlohmann::ordered_json;

// Geometry stored compressed or sparse, decoded when the document is read (decode.hpp): what
// accessor_bytes reads in place of the stored bytes.
struct DecodedGeometry {
  std::map<std::size_t, std::vector<unsigned char>> views;      // EXT_meshopt_compression views
  std::map<std::size_t, std::vector<unsigned char>> accessors;  // Draco primitives' and sparse
                                                                // accessors' elements, tightly packed
  std::vector<std::string> notes;  // what was decoded, for the report
};

struct Document {
  std::string file;               // as given, for errors
  std::filesystem::path folder;   // absolute: relative URIs resolve here
  Json json;
  std::vector<std::vector<unsigned char>> buffers;  // the bytes of json["buffers"][i]
  int added_buffer = -1;          // the buffer add_view appends to, once there is one
  // Files made here, by relative URI (images): written beside a .gltf, embedded in a .glb.
  std::map<std::string, std::string> new_files;
  // The files the command read besides this document (a bake's high-poly and cage, and what they
  // reference): write_document writes none of them, as none of the document's own.
  std::vector<std::filesystem::path> other_inputs;
  // Files written beside the output whatever its kind, by name: a bake's maps that are not the
  // materials' textures. Never embedded; checked with the document's own files (no name twice, no
  // input, inside the output's folder) and written only when all of them pass.
  std::map<std::string, std::string> beside;
  DecodedGeometry decoded;
};

// .gltf or .glb, read once. Every core property's type is checked first (types.hpp), then every
// index (references.hpp); buffer and image URIs must stay inside the file's folder; image files must
// exist (they are copied or embedded on write); compressed and sparse geometry is decoded
// (decode.hpp); every accessor lies within its buffer view and every view within its buffer.
Result<Document> read_document(const std::filesystem::path& path);

// Where accessor `index`'s elements lie: its decoded elements (Draco, sparse) when it has them, else
// in doc.buffers or a decoded meshopt view, checked against its buffer view and that view against
// its buffer. A plain accessor without a buffer view is refused.
struct AccessorBytes {
  const unsigned char* first = nullptr;  // element 0
  std::size_t count = 0, stride = 0;     // stride: bytes from one element to the next
  int component_type = 0;                // 5120 (byte) ... 5126 (float)
  std::size_t components = 0;            // 1 (SCALAR) ... 16 (MAT4)
  std::size_t component_size = 0;        // bytes
  bool normalized = false;
};
Result<AccessorBytes> accessor_bytes(const Document& doc, std::size_t index);

// The bytes of buffer view `index`: decoded (meshopt) or in its buffer, checked.
Result<std::span<const unsigned char>> view_bytes(const Document& doc, std::size_t index);

// Components of an accessor type ("VEC3": 3; 0 when unknown); bytes of a componentType (0 when unknown).
std::size_t components_of(const std::string& type);
std::size_t component_size_of(int component_type);

// accessor.componentType values.
constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125, kFloat = 5126;

// One component at `p` as a float: FLOAT as stored, integers as KHR_mesh_quantization reads them
// (normalized: unsigned v / max, signed max(v / max, −1); else the integer's value); 0 for an unknown type.
float component_value(const unsigned char* p, int component_type, bool normalized);
// One index at `p` (unsigned byte, short or int).
std::uint32_t index_value(const unsigned char* p, int component_type);

constexpr int kTriangles = 4;              // primitive.mode of triangle lists (the default)
constexpr int kArrayBuffer = 34962;         // bufferView.target of vertex attributes
constexpr int kElementArrayBuffer = 34963;  // and of indices

// Appends `bytes` (4-byte aligned) as a new buffer view; returns its index. target 0: none.
int add_view(Document& doc, std::span<const unsigned char> bytes, int target);

// A new index accessor over `indices` (unsigned short where `vertices` allows, else unsigned int);
// returns its index.
int add_index_accessor(Document& doc, const std::vector<std::uint32_t>& indices, std::size_t vertices);

// A new float accessor of `count` elements of `type` ("SCALAR", "VEC3", "VEC4") over `values`
// (count × components floats); returns its index.
int add_float_accessor(Document& doc, const std::vector<float>& values, std::size_t count, const char* type);

// Writes `doc` as `output`: .gltf (JSON, with every buffer merged into one `<stem>.bin` beside it
// and images referenced by URI copied beside it when the folder differs) or .glb (one BIN chunk
// holding every buffer and every image). Each file goes through a temporary file and a rename, the
// .gltf or .glb last. Refuses, before writing anything, to write over any file the document was read
// from or `other_inputs`, and an image whose real path leaves the output's folder (a link on the
// way). Returns the files written, the .gltf or .glb last.
Result<std::vector<std::filesystem::path>> write_document(const Document& doc, const std::filesystem::path& output);

// The encoded bytes of image `index`: a file beside the document, a data: URI, a buffer view, or
// one of new_files.
Result<std::string> image_bytes(const Document& doc, std::size_t index);

// json[key] when it is an array, else an empty array: a glTF's optional lists read without checks.
const Json& array_in(const Json& json, const char* key);

// object[key] as an integer of type T: `fallback` when absent, `invalid` when it is not an integer
// T holds. nlohmann's value() converts a float such as 2e45 to an integer type with undefined
// behaviour (found by fuzzing), so every integer of a glTF is read through this.
template <class T>
T integer_in(const Json& object, const char* key, T fallback, T invalid) {
  const auto it = object.find(key);
  if (it == object.end()) return fallback;
  if (it->is_number_unsigned()) {
    const std::uint64_t v = it->get<std::uint64_t>();
    return v <= std::uint64_t(std::numeric_limits<T>::max()) ? T(v) : invalid;
  }
  if (it->is_number_integer()) {  // signed storage (parsed negatives, or set from an int)
    const std::int64_t v = it->get<std::int64_t>();
    if constexpr (std::is_signed_v<T>) return v >= std::numeric_limits<T>::min() && v <= std::numeric_limits<T>::max() ? T(v) : invalid;
    return v >= 0 && std::uint64_t(v) <= std::uint64_t(std::numeric_limits<T>::max()) ? T(v) : invalid;
  }
  return invalid;
}

// object's "name" when it is a string, else `fallback` (names are for messages and reports: one of
// another type is no reason to stop).
inline std::string name_in(const Json& object, std::string fallback) {
  if (!object.is_object()) return fallback;
  const auto it = object.find("name");
  return it != object.end() && it->is_string() ? it->get<std::string>() : fallback;
}

// A size, offset or index: SIZE_MAX (which every bounds check refuses) when not a valid integer.
inline std::size_t size_in(const Json& object, const char* key, std::size_t fallback) {
  return integer_in<std::size_t>(object, key, fallback, SIZE_MAX);
}

// The JSON of a .gltf or .glb alone (a GLB's JSON chunk read alone; no buffers read, nothing
// checked but the container and the size and depth limits of io/bounded_json.hpp).
Result<Json> read_json(const std::filesystem::path& path);

// The files a document is read from: `file` itself, then its buffers' and images' URIs that are
// neither data: URIs nor in `made` (absolute, normalized; whether they exist is not checked).
std::vector<std::filesystem::path> source_files(const std::filesystem::path& file, const Json& json,
                                                const std::map<std::string, std::string>& made = {});

// Percent-decoding of a relative URI (RFC 3986), as glTF URIs are written.
std::string decode_uri(const std::string& uri);

}  // namespace matbake::gltf
