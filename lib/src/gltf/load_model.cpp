#include "load_model.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>

namespace matbake::gltf {
namespace fs = std::filesystem;
namespace {

struct ConfinedFolder {
  fs::path base;         // absolute
  std::string refused;   // the first URI refused, with the reason
};

// tinygltf passes the URI joined to the folder (or as is, when absolute).
std::string expand_path(const std::string& path, void* user) {
  auto* folder = static_cast<ConfinedFolder*>(user);
  if (!is_inside(folder->base, path) || path.find("://") != std::string::npos) {
    if (folder->refused.empty()) {
      // Said as written in the file where possible (tinygltf hands over the joined path).
      const fs::path relative = fs::path(path).lexically_relative(folder->base);
      folder->refused = "URI '" + (relative.empty() ? path : relative.string()) +
                        "' is outside the glTF's folder; only files beside it are read";
    }
    return {};
  }
  return path;
}

bool file_exists(const std::string& path, void* user) {
  std::error_code ec;
  return !path.empty() && is_inside(static_cast<ConfinedFolder*>(user)->base, path) && fs::is_regular_file(path, ec);
}

bool read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  if (!file_exists(path, user)) {
    if (err) *err += "cannot read " + path + "\n";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return bool(in) || in.eof();
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

Status load_model(const fs::path& path, tinygltf::Model& model) {
  const std::string file = path.string();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Error{file, "no such file"};
  ConfinedFolder folder{fs::absolute(path).parent_path(), {}};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({file_exists, expand_path, read_file, refuse_write, &folder});
  loader.SetImageLoader(skip_image_decoding, nullptr);
  std::string err, warn;
  const std::string absolute = fs::absolute(path).string();
  const bool ok = path.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, absolute)
                                              : loader.LoadASCIIFromFile(&model, &err, &warn, absolute);
  if (!folder.refused.empty()) return Error{file, folder.refused};
  if (!ok) return Error{file, "not a valid glTF: " + first_line(err)};
  return success();
}

}  // namespace matbake::gltf
