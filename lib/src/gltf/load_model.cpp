#include "load_model.hpp"

#include "document.hpp"
#include "matbake/read_file.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>

namespace matbake::gltf {
namespace fs = std::filesystem;
namespace {

struct ConfinedFolder {
  fs::path base;         // absolute
  std::string refused;   // the first URI refused, with the reason
  std::vector<unsigned char>* glb_bin = nullptr;  // served for kGlbBinUri
  std::set<fs::path> buffer_files;  // what is read whole; any other file (an image) only checked
};

bool is_glb_bin(const std::string& path, const ConfinedFolder* folder) {
  return folder->glb_bin != nullptr && path.ends_with(kGlbBinUri);
}

bool is_served(const std::string& path, const ConfinedFolder* folder) {
  return is_glb_bin(path, folder) || path.ends_with(kEmptyBufferUri);
}

// tinygltf asks for the URI joined to the folder ("folder/" + uri, even when the URI is absolute),
// then for "./" + uri. The URI as written decides: absolute, climbing above the folder with .., or
// naming a scheme is refused (and remembered, so the error says which); otherwise the joined path
// is the file, and the "./" retry finds nothing.
std::string expand_path(const std::string& path, void* user) {
  auto* folder = static_cast<ConfinedFolder*>(user);
  if (is_served(path, folder)) return path;
  const std::string prefix = folder->base.string() + "/";
  const bool joined = path.rfind(prefix, 0) == 0;
  const std::string uri = joined ? path.substr(prefix.size()) : path.rfind("./", 0) == 0 ? path.substr(2) : path;
  const fs::path normal = fs::path(uri).lexically_normal();
  const bool outside = fs::path(uri).is_absolute() || uri.find("://") != std::string::npos ||
                       (!normal.empty() && *normal.begin() == "..");
  if (outside) {
    if (folder->refused.empty()) {
      folder->refused = "URI '" + uri + "' is outside the glTF's folder; only files beside it are read";
    }
    return {};
  }
  return joined ? path : std::string();
}

bool file_exists(const std::string& path, void* user) {
  if (is_served(path, static_cast<ConfinedFolder*>(user))) return true;
  auto* folder = static_cast<ConfinedFolder*>(user);
  if (path.empty() || !is_inside(folder->base, path)) return false;
  if (!is_really_inside(folder->base, path)) {
    if (folder->refused.empty()) {
      // Appended, not "'" + std::string: GCC 12 at -O3 misreads that (a false -Wstringop-overflow).
      folder->refused = fs::path(path).lexically_relative(folder->base).string();
      folder->refused.insert(0, 1, '\'');
      folder->refused += "' is a link to a file outside the glTF's folder; only files beside it are read";
    }
    return false;
  }
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

bool read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  if (auto* folder = static_cast<ConfinedFolder*>(user); is_glb_bin(path, folder)) {
    out->swap(*folder->glb_bin);
    return true;
  }
  if (path.ends_with(kEmptyBufferUri)) {
    out->assign(1, 0);  // tinygltf refuses an empty file
    return true;
  }
  if (!file_exists(path, user)) {
    if (err) *err += "cannot read " + path + "\n";
    return false;
  }
  if (!static_cast<ConfinedFolder*>(user)->buffer_files.contains(fs::path(path).lexically_normal())) {
    out->assign(1, 0);  // an image: its pixels are never decoded here, so its bytes are not read
    return true;
  }
  if (!read_whole_file(path, *out)) {
    if (err) *err += "cannot read " + path + "\n";
    return false;
  }
  return true;
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "matbake does not write while loading\n";
  return false;
}

// matbake needs image files to exist, not their pixels.
bool skip_image_decoding(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                         void*) {
  return true;
}

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line.empty() ? "unknown error" : line;
}

}  // namespace

bool is_inside(const fs::path& base, const fs::path& path) {
  const fs::path b = base.lexically_normal(), q = path.lexically_normal();
  auto [bi, qi] = std::mismatch(b.begin(), b.end(), q.begin(), q.end());
  return bi == b.end() || (std::next(bi) == b.end() && bi->empty());  // "dir/" ends in an empty element
}

Status load_model_json(const fs::path& path, const std::string& json_text, std::vector<unsigned char>& glb_bin,
                       const std::vector<std::string>& buffer_uris, tinygltf::Model& model) {
  const std::string file = path.string();
  ConfinedFolder folder{fs::absolute(path).parent_path(), {}, &glb_bin, {}};
  for (const std::string& uri : buffer_uris) {  // as written and percent-decoded: tinygltf asks for one of them
    folder.buffer_files.insert((folder.base / uri).lexically_normal());
    folder.buffer_files.insert((folder.base / decode_uri(uri)).lexically_normal());
  }
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({file_exists, expand_path, read_file, refuse_write, &folder});
  loader.SetImageLoader(skip_image_decoding, nullptr);
  if (json_text.size() > std::numeric_limits<unsigned>::max()) return Error{file, "larger than 4 GiB, which tinygltf cannot read"};
  std::string err, warn;
  const std::string base = folder.base.string();
  const bool ok = loader.LoadASCIIFromString(&model, &err, &warn, json_text.data(), unsigned(json_text.size()), base);
  if (!folder.refused.empty()) return Error{file, folder.refused};
  if (!ok) return Error{file, "not a valid glTF: " + first_line(err)};
  return success();
}

}  // namespace matbake::gltf
