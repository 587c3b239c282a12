#include "document.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <deque>
#include <fstream>
#include <iterator>

#include "decode.hpp"
#include "../io/bounded_json.hpp"
#include "json_text.hpp"
#include "load_model.hpp"
#include "references.hpp"
#include "types.hpp"
#include "matbake/output_check.hpp"
#include "matbake/read_file.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/version.hpp"

namespace matbake::gltf {
namespace fs = std::filesystem;
namespace {

static_assert(std::endian::native == std::endian::little, "GLB is little-endian; so are the bytes written as is");

std::string read_bytes(const fs::path& path) {
  std::string bytes;
  if (!read_whole_file(path, bytes)) bytes.clear();
  return bytes;
}

std::uint32_t u32_at(const std::string& bytes, std::size_t offset) {
  std::uint32_t v = 0;
  if (offset + 4 <= bytes.size()) std::memcpy(&v, bytes.data() + offset, 4);
  return v;
}

bool is_data_uri(const std::string& uri) { return uri.rfind("data:", 0) == 0; }

void pad(std::string& bytes, std::size_t alignment, char fill) {
  bytes.resize((bytes.size() + alignment - 1) / alignment * alignment, fill);
}

// The MIME type glTF wants on an image held in a buffer view.
std::string mime_type_of(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return "image/png";
  if (ext == ".jpg" || ext == ".jpeg") return "image/jpeg";
  if (ext == ".webp") return "image/webp";
  if (ext == ".ktx2") return "image/ktx2";
  return {};
}

void append_u32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

// A GLB read chunk by chunk: its JSON, and its BIN chunk (empty when it has none).
struct Glb {
  Json json;
  std::vector<unsigned char> bin;
};
// A glTF's JSON text, from a .gltf file or a GLB's chunk: within the size and depth limits
// (io/bounded_json.hpp) and an object.
constexpr std::size_t kJsonLimit = std::size_t(512) << 20;  // far past any scene's: the bytes live in buffers

Result<Json> parse_gltf_json(const fs::path& path, std::string_view text) {
  std::string problem;
  Json json = parse_bounded_json<Json>(text, kJsonLimit, problem);
  if (!problem.empty() && json_limit_problem(text, kJsonLimit).empty()) problem = "not a valid glTF: the JSON is malformed";
  if (problem.empty() && !json.is_object()) problem = "not a valid glTF: the JSON is not an object";
  if (!problem.empty()) return Error{path.string(), problem};
  return json;
}

// With `with_bin` false, the JSON chunk alone is read (what the plan and the bake's input hashing need).
Result<Glb> read_glb(const fs::path& path, bool with_bin = true) {
  const auto bad = [&](const std::string& what) { return Error{path.string(), "not a valid glTF: " + what}; };
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return Error{path.string(), "cannot be read"};
  const std::uint64_t size = std::uint64_t(in.tellg());
  in.seekg(0);
  std::string header(20, '\0');
  if (size < 20 || !in.read(header.data(), 20)) return bad("shorter than a GLB header");
  if (header.compare(0, 4, "glTF") != 0 || u32_at(header, 4) != 2) return bad("not a GLB 2 file");
  const std::uint64_t json_length = u32_at(header, 12);
  if (header.compare(16, 4, "JSON") != 0 || 20 + json_length > size) return bad("the GLB's JSON chunk is truncated");
  if (json_length > kJsonLimit) return Error{path.string(), json_size_problem(json_length, kJsonLimit)};
  std::string text(json_length, '\0');
  if (!in.read(text.data(), std::streamsize(json_length))) return bad("the GLB's JSON chunk is truncated");
  Glb glb;
  auto json = parse_gltf_json(path, text);
  if (!json) return json.error();
  glb.json = std::move(*json);
  const std::uint64_t bin_at = 20 + (json_length + 3) / 4 * 4;
  if (with_bin && bin_at + 8 <= size) {
    std::string chunk(8, '\0');
    in.seekg(std::streamoff(bin_at));
    if (!in.read(chunk.data(), 8)) return bad("the GLB's BIN chunk is truncated");
    const std::uint64_t bin_length = u32_at(chunk, 0);
    if (chunk.compare(4, 4, std::string("BIN\0", 4)) == 0) {
      if (bin_at + 8 + bin_length > size) return bad("the GLB's BIN chunk is truncated");
      glb.bin.resize(bin_length);
      if (bin_length && !in.read(reinterpret_cast<char*>(glb.bin.data()), std::streamsize(bin_length))) {
        return bad("the GLB's BIN chunk is truncated");
      }
    }
  }
  return glb;
}

// A file's contents as pieces written one after another: views of bytes that live elsewhere, and
// the few it owns (padding, embedded images).
struct Chunks {
  std::vector<std::string_view> parts;
  std::deque<std::string> owned;  // stable addresses
  std::size_t size = 0;
  void add(std::string_view bytes) {
    parts.push_back(bytes);
    size += bytes.size();
  }
  void add_owned(std::string bytes) { add(owned.emplace_back(std::move(bytes))); }
  void pad() {
    if (size % 4) add_owned(std::string(4 - size % 4, '\0'));
  }
};

// The JSON tinygltf is given to read the buffers. It knows neither Draco (it refuses an indices
// accessor without a view) nor meshopt's fallback buffers (it wants a URI), so meshes are left out
// (check_references and the readers of accessors check them) and a fallback buffer becomes an
// empty one. A GLB's buffer 0 is served from its BIN chunk (kGlbBinUri), cut to its byteLength.
Json for_tinygltf(const Json& json, bool glb, std::vector<unsigned char>& glb_bin) {
  Json copy = json;
  copy.erase("meshes");
  if (!copy.contains("buffers") || !copy["buffers"].is_array()) return copy;
  Json& buffers = copy["buffers"];
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    if (is_fallback_buffer(json, i)) buffers[i] = {{"byteLength", 1}, {"uri", kEmptyBufferUri}};
  }
  if (glb && !buffers.empty() && buffers[0].is_object() && !buffers[0].contains("uri")) {
    buffers[0]["uri"] = kGlbBinUri;
    const std::size_t length = size_in(buffers[0], "byteLength", 0);  // the chunk may carry 3 bytes of padding
    if (glb_bin.size() > length) glb_bin.resize(length);
  }
  return copy;
}

// Every view within its buffer and every accessor with a view within it (the bytes a writer copies).
Status check_accessors(const Document& doc) {
  const Json& views = array_in(doc.json, "bufferViews");
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (auto bytes = view_bytes(doc, v); !bytes) return bytes.error();
  }
  const Json& accessors = array_in(doc.json, "accessors");
  for (std::size_t a = 0; a < accessors.size(); ++a) {
    if (!accessors[a].contains("bufferView")) continue;  // all zeros (or sparse values alone)
    if (auto bytes = accessor_bytes(doc, a); !bytes) return bytes.error();
  }
  return success();
}

// asset.generator names matbake, which wrote every byte of the file; the input's own generator (what
// made the geometry) is kept as asset.extras.source_generator where extras can hold it.
void name_generator(Json& json) {
  Json& asset = json["asset"];
  if (!asset.is_object()) asset = Json{{"version", "2.0"}};
  const std::string mine = std::string("matbake ") + version;
  const Json given = asset.value("generator", Json());
  if (given.is_string() && given != mine && (!asset.contains("extras") || asset["extras"].is_object())) {
    asset["extras"]["source_generator"] = given;
  }
  asset["generator"] = mine;
}

}  // namespace

std::size_t components_of(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

float component_value(const unsigned char* p, int component_type, bool normalized) {
  const auto as = [p]<class T>(T) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
  };
  switch (component_type) {
    case kFloat: return as(float{});
    case kByte: {
      const float v = float(as(std::int8_t{}));
      return normalized ? std::max(v / 127.0f, -1.0f) : v;
    }
    case kUnsignedByte: {
      const float v = float(as(std::uint8_t{}));
      return normalized ? v / 255.0f : v;
    }
    case kShort: {
      const float v = float(as(std::int16_t{}));
      return normalized ? std::max(v / 32767.0f, -1.0f) : v;
    }
    case kUnsignedShort: {
      const float v = float(as(std::uint16_t{}));
      return normalized ? v / 65535.0f : v;
    }
    case kUnsignedInt: return float(as(std::uint32_t{}));
    default: return 0.0f;
  }
}

std::uint32_t index_value(const unsigned char* p, int component_type) {
  switch (component_type) {
    case kUnsignedByte: return *p;
    case kUnsignedShort: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    default: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

std::size_t component_size_of(int component_type) {
  switch (component_type) {
    case 5120: case 5121: return 1;  // byte, unsigned byte
    case 5122: case 5123: return 2;  // short, unsigned short
    case 5125: case 5126: return 4;  // unsigned int, float
    default: return 0;
  }
}

const Json& array_in(const Json& json, const char* key) {
  static const Json empty = Json::array();
  return json.contains(key) && json[key].is_array() ? json[key] : empty;
}

std::string decode_uri(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uri[i + 1]) && std::isxdigit(uri[i + 2])) {
      out += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

Result<std::string> image_bytes(const Document& doc, std::size_t index) {
  return guarded(doc.file, [&]() -> Result<std::string> {
    const std::string what = "image " + std::to_string(index);
    if (!doc.json.contains("images") || index >= doc.json["images"].size()) return Error{doc.file, what + " does not exist"};
    const Json& image = doc.json["images"][index];
    if (image.contains("bufferView")) {
      const std::size_t v = image["bufferView"].get<std::size_t>();
      if (!doc.json.contains("bufferViews") || v >= doc.json["bufferViews"].size()) return Error{doc.file, what + ": no such buffer view"};
      const Json& view = doc.json["bufferViews"][v];
      const std::size_t buffer = size_in(view, "buffer", 0), offset = size_in(view, "byteOffset", 0),
                        length = size_in(view, "byteLength", 0);
      if (buffer >= doc.buffers.size() || offset + length > doc.buffers[buffer].size()) {
        return Error{doc.file, what + ": its buffer view reaches beyond its buffer"};
      }
      return std::string(reinterpret_cast<const char*>(doc.buffers[buffer].data()) + offset, length);
    }
    const std::string uri = image.value("uri", "");
    if (uri.empty()) return Error{doc.file, what + " has neither a URI nor a buffer view"};
    if (const auto made = doc.new_files.find(uri); made != doc.new_files.end()) return made->second;
    if (is_data_uri(uri)) {
      std::vector<unsigned char> decoded;
      std::string uri_copy = uri, mime;
      if (!tinygltf::DecodeDataURI(&decoded, mime, uri_copy, 0, false)) return Error{doc.file, what + ": its data: URI cannot be decoded"};
      return std::string(decoded.begin(), decoded.end());
    }
    const fs::path path = doc.folder / decode_uri(uri);
    if (!is_inside(doc.folder, path)) return Error{doc.file, what + ": URI '" + uri + "' is outside the glTF's folder"};
    if (!is_really_inside(doc.folder, path)) {
      return Error{doc.file, what + ": '" + uri + "' is a link to a file outside the glTF's folder"};
    }
    std::string bytes = read_bytes(path);
    if (bytes.empty()) return Error{doc.file, what + ": '" + uri + "' cannot be read"};
    return bytes;
  });
}

Result<std::span<const unsigned char>> view_bytes(const Document& doc, std::size_t index) {
  const std::string name = "buffer view " + std::to_string(index);
  const Json& views = array_in(doc.json, "bufferViews");
  if (index >= views.size()) return Error{doc.file, name + " does not exist"};
  if (const auto decoded = doc.decoded.views.find(index); decoded != doc.decoded.views.end()) {
    return std::span<const unsigned char>(decoded->second);
  }
  const Json& view = views[index];
  const std::size_t buffer = size_in(view, "buffer", SIZE_MAX);
  const std::size_t offset = size_in(view, "byteOffset", 0), length = size_in(view, "byteLength", 0);
  if (buffer < doc.buffers.size() && is_fallback_buffer(doc.json, buffer)) {
    return Error{doc.file, name + " lies in a meshopt fallback buffer (no bytes) but is not compressed"};
  }
  if (buffer >= doc.buffers.size() || offset > doc.buffers[buffer].size() || length > doc.buffers[buffer].size() - offset) {
    return Error{doc.file, name + " reaches beyond its buffer"};
  }
  return std::span<const unsigned char>(doc.buffers[buffer].data() + offset, length);
}

Result<AccessorBytes> accessor_bytes(const Document& doc, std::size_t index) {
  const std::string name = "accessor " + std::to_string(index);
  const Json& accessors = array_in(doc.json, "accessors");
  if (index >= accessors.size()) return Error{doc.file, name + " does not exist"};
  const Json& accessor = accessors[index];
  AccessorBytes out;
  out.component_type = integer_in(accessor, "componentType", 0, 0);  // 0: an unknown type
  out.components = components_of(accessor.value("type", ""));
  out.component_size = component_size_of(out.component_type);
  if (out.components == 0 || out.component_size == 0) return Error{doc.file, name + " has an unknown type"};
  out.count = size_in(accessor, "count", 0);
  out.normalized = accessor.value("normalized", false);
  const std::size_t element = out.components * out.component_size;
  if (const auto decoded = doc.decoded.accessors.find(index); decoded != doc.decoded.accessors.end()) {
    out.first = decoded->second.data();  // sized count × element when decoded
    out.stride = element;
    return out;
  }
  if (!accessor.contains("bufferView")) return Error{doc.file, name + " has no buffer view"};
  auto view = view_bytes(doc, size_in(accessor, "bufferView", SIZE_MAX));
  if (!view) return view.error();
  const std::size_t length = view->size();
  out.stride = size_in(array_in(doc.json, "bufferViews")[size_in(accessor, "bufferView", 0)], "byteStride", element);
  const std::size_t offset = size_in(accessor, "byteOffset", 0);
  // offset + stride (count − 1) + element ≤ length, without overflow for a hostile count.
  const bool fits = out.count == 0 || (offset <= length && element <= length - offset &&
                                       (out.stride == 0 || out.count - 1 <= (length - offset - element) / out.stride));
  if (!fits) return Error{doc.file, name + " reaches beyond its buffer"};
  out.first = view->data() + offset;
  return out;
}

// A .gltf's text, refused by its size before it is read.
Result<std::string> gltf_text(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Error{path.string(), "cannot read the glTF (missing or not a file)"};
  if (std::string problem = json_size_problem(fs::file_size(path, ec), kJsonLimit); !problem.empty()) return Error{path.string(), problem};
  std::string bytes;
  if (!read_whole_file(path, bytes)) return Error{path.string(), "cannot be read"};
  return bytes;
}

Result<Json> read_json(const fs::path& path) {
  return guarded(path.string(), [&]() -> Result<Json> {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return Error{path.string(), "cannot read the glTF (missing or not a file)"};
    if (path.extension() == ".glb") {
      auto glb = read_glb(path, false);
      if (!glb) return glb.error();
      return std::move(glb->json);
    }
    auto text = gltf_text(path);
    if (!text) return text.error();
    return parse_gltf_json(path, *text);
  });
}

std::vector<fs::path> source_files(const fs::path& file, const Json& json, const std::map<std::string, std::string>& made) {
  const fs::path absolute = fs::absolute(file).lexically_normal();
  std::vector<fs::path> files = {absolute};
  for (const char* array : {"buffers", "images"}) {
    if (!json.contains(array) || !json[array].is_array()) continue;
    for (const Json& item : json[array]) {
      const std::string uri = item.is_object() ? item.value("uri", "") : "";
      if (!uri.empty() && !is_data_uri(uri) && !made.contains(uri)) {
        files.push_back((absolute.parent_path() / decode_uri(uri)).lexically_normal());
      }
    }
  }
  return files;
}

Result<Document> read_document(const fs::path& path) {
  return guarded(path.string(), [&]() -> Result<Document> {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return Error{path.string(), "no such file"};
    Document doc;
    doc.file = path.string();
    doc.folder = fs::absolute(path).parent_path();
    std::vector<unsigned char> glb_bin;
    if (path.extension() == ".glb") {
      // The BIN chunk is read straight into the buffer tinygltf takes over: a large scene's bytes
      // are in memory once.
      auto glb = read_glb(path);
      if (!glb) return glb.error();
      doc.json = std::move(glb->json);
      glb_bin = std::move(glb->bin);
    } else {
      auto text = gltf_text(path);
      if (!text) return text.error();
      auto json = parse_gltf_json(path, *text);
      if (!json) return json.error();
      doc.json = std::move(*json);
    }
    if (Status s = check_types(doc.file, doc.json); !s) return s.error();
    if (Status s = check_references(doc.file, doc.json); !s) return s.error();
    tinygltf::Model model;  // tinygltf reads the buffers: data: URIs, files beside the glTF, sizes
    std::vector<std::string> buffer_uris;
    for (const Json& buffer : array_in(doc.json, "buffers")) {
      if (buffer.contains("uri") && buffer["uri"].is_string()) buffer_uris.push_back(buffer["uri"].get<std::string>());
    }
    if (Status loaded = load_model_json(path, for_tinygltf(doc.json, path.extension() == ".glb", glb_bin).dump(), glb_bin, buffer_uris, model);
        !loaded) {
      return loaded.error();
    }
    const std::size_t declared = array_in(doc.json, "buffers").size();
    if (declared != model.buffers.size()) return Error{doc.file, "not a valid glTF: buffers could not all be read"};
    for (std::size_t i = 0; i < model.buffers.size(); ++i) {
      std::vector<unsigned char> data = std::move(model.buffers[i].data);
      if (is_fallback_buffer(doc.json, i)) data.clear();
      // A GLB's BIN chunk may carry up to 3 bytes of padding beyond the buffer's byteLength.
      data.resize(std::min(data.size(), std::size_t(size_in(doc.json["buffers"][i], "byteLength", 0))));
      doc.buffers.push_back(std::move(data));
    }
    if (Status s = decode_meshopt_views(doc); !s) return s.error();
    if (Status s = check_accessors(doc); !s) return s.error();
    if (Status s = decode_draco_and_sparse(doc); !s) return s.error();
    return doc;
  });
}

int add_view(Document& doc, std::span<const unsigned char> bytes, int target) {
  if (doc.added_buffer < 0) {
    doc.buffers.emplace_back();
    doc.json["buffers"].push_back({{"byteLength", 0}});
    doc.added_buffer = int(doc.buffers.size()) - 1;
  }
  std::vector<unsigned char>& buffer = doc.buffers[std::size_t(doc.added_buffer)];
  buffer.resize((buffer.size() + 3) / 4 * 4, 0);
  const std::size_t offset = buffer.size();
  buffer.insert(buffer.end(), bytes.begin(), bytes.end());
  doc.json["buffers"][std::size_t(doc.added_buffer)]["byteLength"] = buffer.size();
  Json view = {{"buffer", doc.added_buffer}, {"byteOffset", offset}, {"byteLength", bytes.size()}};
  if (target) view["target"] = target;
  doc.json["bufferViews"].push_back(std::move(view));
  return int(doc.json["bufferViews"].size()) - 1;
}

int add_index_accessor(Document& doc, const std::vector<std::uint32_t>& indices, std::size_t vertices) {
  std::vector<unsigned char> bytes;
  const bool narrow = vertices <= 65535;
  for (std::uint32_t i : indices) {
    const unsigned char* p = reinterpret_cast<const unsigned char*>(&i);  // little-endian, as glTF
    bytes.insert(bytes.end(), p, p + (narrow ? 2 : 4));
  }
  const int view = add_view(doc, bytes, kElementArrayBuffer);
  doc.json["accessors"].push_back(
      {{"bufferView", view}, {"componentType", narrow ? kUnsignedShort : kUnsignedInt}, {"count", indices.size()}, {"type", "SCALAR"}});
  return int(doc.json["accessors"].size()) - 1;
}

int add_float_accessor(Document& doc, const std::vector<float>& values, std::size_t count, const char* type) {
  const std::span bytes(reinterpret_cast<const unsigned char*>(values.data()), values.size() * sizeof(float));
  const int view = add_view(doc, bytes, kArrayBuffer);
  doc.json["accessors"].push_back({{"bufferView", view}, {"componentType", 5126}, {"count", count}, {"type", type}});
  return int(doc.json["accessors"].size()) - 1;
}

Result<std::vector<fs::path>> write_document(const Document& doc, const fs::path& output) {
  return guarded(output.string(), [&]() -> Result<std::vector<fs::path>> {
    const std::string out_name = output.string();
    const std::string ext = output.extension().string();
    if (ext != ".gltf" && ext != ".glb") return Error{out_name, "the output is .gltf or .glb", true};
    const bool glb = ext == ".glb";
    const fs::path out_folder = fs::absolute(output).parent_path().lexically_normal();
    const fs::path bin_path = output.parent_path() / (output.stem().string() + ".bin");

    // Every file the document came from, none of which may be written.
    // (The one output rule: by real path and inode, so a link to an input is one too.)
    std::vector<fs::path> inputs = source_files(doc.file, doc.json, doc.new_files);
    inputs.insert(inputs.end(), doc.other_inputs.begin(), doc.other_inputs.end());
    const NamedOutput files_out[] = {{output, "glTF output"}, {glb ? fs::path() : bin_path, "its buffer"}};
    if (Status s = check_outputs(files_out, inputs); !s) return s.error();

    // All buffers become one: each starts 4-byte aligned, the views move with it. Meshopt fallback
    // buffers (no bytes) stay buffers of their own after it, and their views keep their offsets.
    Json json = doc.json;
    name_generator(json);
    Chunks bin;  // the merged buffer as pieces of the document's own bytes: a large scene is not copied
    std::vector<std::size_t> base(doc.buffers.size());
    Json fallbacks = Json::array();
    for (std::size_t i = 0; i < doc.buffers.size(); ++i) {
      if (is_fallback_buffer(doc.json, i)) {
        base[i] = SIZE_MAX;
        fallbacks.push_back(doc.json["buffers"][i]);
        continue;
      }
      bin.pad();
      base[i] = bin.size;
      bin.add({reinterpret_cast<const char*>(doc.buffers[i].data()), doc.buffers[i].size()});
    }
    const auto move_range = [&](Json& holder) -> bool {  // holder's buffer and byteOffset, in the merged layout
      const std::size_t buffer = size_in(holder, "buffer", 0);
      if (buffer >= base.size()) return false;
      if (base[buffer] == SIZE_MAX) {
        holder["buffer"] = 1 + std::count(base.begin(), base.begin() + std::ptrdiff_t(buffer), SIZE_MAX);
        return true;
      }
      holder["buffer"] = 0;
      holder["byteOffset"] = base[buffer] + size_in(holder, "byteOffset", 0);
      return true;
    };
    if (json.contains("bufferViews")) {
      for (Json& view : json["bufferViews"]) {
        if (!move_range(view)) return Error{doc.file, "a buffer view names a buffer that does not exist"};
        if (view.contains("extensions") && view["extensions"].contains("EXT_meshopt_compression")) {
          if (!move_range(view["extensions"]["EXT_meshopt_compression"])) return Error{doc.file, "a compressed view names a buffer that does not exist"};
        }
      }
    }

    // Images by URI: embedded in a .glb (a GLB holds no URIs, data: ones included); written beside a
    // .gltf when made here, copied beside it when the folder differs.
    std::vector<std::pair<fs::path, std::string>> files;  // written beside the output: target, bytes
    if (json.contains("images")) {
      for (std::size_t i = 0; i < json["images"].size(); ++i) {
        Json& image = json["images"][i];
        const std::string uri = image.value("uri", "");
        if (uri.empty() || (!glb && is_data_uri(uri))) continue;
        const bool made = doc.new_files.contains(uri);
        if (!glb && !made && out_folder == doc.folder.lexically_normal()) continue;
        auto bytes = image_bytes(doc, i);
        if (!bytes) return bytes.error();
        if (!glb) {
          const fs::path target = output.parent_path() / decode_uri(uri);
          const NamedOutput image_file{target, "image '" + uri + "'"};
          if (Status s = check_outputs(std::span(&image_file, 1), inputs); !s) return s.error();
          if (!is_really_inside(out_folder, target)) {
            return Error{target.string(), "leaves the output's folder (a link on the way); matbake writes only inside it", true};
          }
          files.emplace_back(target, std::move(*bytes));
          continue;
        }
        std::string mime = image.value("mimeType", "");
        if (mime.empty() && is_data_uri(uri)) mime = uri.substr(5, uri.find(';') - 5);
        if (mime.empty()) mime = mime_type_of(decode_uri(uri));
        if (mime.empty()) return Error{doc.file, "image " + std::to_string(i) + ": unknown type, cannot embed it in a GLB"};
        bin.pad();
        json["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size}, {"byteLength", bytes->size()}});
        bin.add_owned(std::move(*bytes));
        image.erase("uri");
        image["bufferView"] = json["bufferViews"].size() - 1;
        image["mimeType"] = mime;
      }
    }
    for (const auto& [name, bytes] : doc.beside) {
      const fs::path target = output.parent_path() / name;
      if (!is_really_inside(out_folder, target)) {
        return Error{target.string(), "leaves the output's folder (a link on the way); matbake writes only inside it", true};
      }
      files.emplace_back(target, bytes);
    }
    // No two of the files beside the output share a name (a map named as a copied image), nor any
    // the output or its buffer.
    std::vector<NamedOutput> beside_outputs(std::begin(files_out), std::end(files_out));
    for (const auto& [target, bytes] : files) beside_outputs.push_back({target, "'" + target.filename().string() + "'"});
    if (Status s = check_outputs(beside_outputs, inputs); !s) return s.error();
    if (bin.size == 0 && fallbacks.empty()) {
      json.erase("buffers");
    } else {
      json["buffers"] = Json::array({{{"byteLength", bin.size}}});
      if (!glb) json["buffers"][0]["uri"] = bin_path.filename().string();
      json["buffers"].insert(json["buffers"].end(), fallbacks.begin(), fallbacks.end());
    }

    std::vector<fs::path> written;
    if (!glb && bin.size != 0) {
      if (Status s = write_file_atomically(bin_path, bin.parts); !s) return s.error();
      written.push_back(bin_path);
    }
    for (const auto& [target, bytes] : files) {
      std::error_code ec;
      fs::create_directories(target.parent_path().empty() ? fs::path(".") : target.parent_path(), ec);
      if (Status s = write_file_atomically(target, bytes); !s) return s.error();
      written.push_back(target);
    }
    if (!glb) {
      if (Status s = write_file_atomically(output, json_text(json, 2) + "\n"); !s) return s.error();
      written.push_back(output);
      return written;
    }

    std::string text = json_text(json);
    pad(text, 4, ' ');
    bin.pad();
    std::string header;  // the GLB header and the JSON chunk; the BIN chunk is written from `bin` as it is
    header += "glTF";
    append_u32(header, 2);
    append_u32(header, std::uint32_t(12 + 8 + text.size() + (bin.size == 0 ? 0 : 8 + bin.size)));
    append_u32(header, std::uint32_t(text.size()));
    header += "JSON";
    header += text;
    std::string bin_header;
    if (bin.size != 0) {
      append_u32(bin_header, std::uint32_t(bin.size));
      bin_header += std::string("BIN\0", 4);
    }
    std::vector<std::string_view> parts = {header, bin_header};
    parts.insert(parts.end(), bin.parts.begin(), bin.parts.end());
    if (Status s = write_file_atomically(output, parts); !s) return s.error();
    written.push_back(output);
    return written;
  });
}

}  // namespace matbake::gltf
