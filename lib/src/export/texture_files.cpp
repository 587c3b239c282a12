#include "texture_files.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <iterator>

#include "matbake/atomic_file.hpp"

namespace matbake::exporter {
namespace fs = std::filesystem;
namespace {

// The extension OIIO picks its reader by, from the bytes' signature.
const char* extension_of(const std::string& bytes) {
  if (bytes.rfind("\x89PNG", 0) == 0) return ".png";
  if (bytes.rfind("\xff\xd8", 0) == 0) return ".jpg";
  if (bytes.size() > 12 && bytes.rfind("RIFF", 0) == 0 && bytes.compare(8, 4, "WEBP") == 0) return ".webp";
  return "";
}

}  // namespace

ImageCache::ImageCache(const gltf::Document& doc) : doc_(doc) {
  static std::atomic<unsigned> counter{0};
  folder_ = fs::temp_directory_path() / ("matbake-export-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
}

ImageCache::~ImageCache() {
  std::error_code ec;
  fs::remove_all(folder_, ec);
}

Result<const image::Image*> ImageCache::texture(int texture, color::Transfer colour) {
  const gltf::Json& json = doc_.json;
  if (texture < 0 || !json.contains("textures") || std::size_t(texture) >= json["textures"].size()) {
    return Error{doc_.file, "texture " + std::to_string(texture) + " does not exist"};
  }
  const gltf::Json& t = json["textures"][std::size_t(texture)];
  if (!t.contains("source")) {
    return Error{doc_.file, "texture " + std::to_string(texture) + " has no PNG or JPEG source matbake could read"};
  }
  const int source = t["source"].get<int>();
  if (const auto found = images_.find({source, colour}); found != images_.end()) return &found->second;
  auto bytes = gltf::image_bytes(doc_, std::size_t(source));
  if (!bytes) return bytes.error();
  std::error_code ec;
  fs::create_directories(folder_, ec);
  const char* extension = extension_of(*bytes);
  if (!*extension) return Error{doc_.file, "image " + std::to_string(source) + " is not PNG, JPEG or WebP"};
  const fs::path file = folder_ / ("image" + std::to_string(files_++) + extension);
  if (Status s = write_file_atomically(file, *bytes); !s) return s.error();
  auto decoded = image::read_image(file, colour);
  fs::remove(file, ec);
  if (!decoded) return Error{doc_.file, "image " + std::to_string(source) + ": " + decoded.error().message};
  return &(images_[{source, colour}] = std::move(*decoded));
}

Status ImageCache::check(std::size_t index) {
  auto bytes = gltf::image_bytes(doc_, index);
  if (!bytes) return bytes.error();
  const std::string what = "image " + std::to_string(index);
  if (bytes->rfind("\xabKTX 20\xbb", 0) == 0) return success();
  const char* extension = extension_of(*bytes);
  if (!*extension) return Error{doc_.file, what + " is not PNG, JPEG, WebP or KTX2"};
  std::error_code ec;
  fs::create_directories(folder_, ec);
  const fs::path file = folder_ / ("check" + std::to_string(files_++) + extension);
  if (Status s = write_file_atomically(file, *bytes); !s) return s.error();
  auto probed = image::probe_image(file);
  fs::remove(file, ec);
  if (!probed) return Error{doc_.file, what + ": " + probed.error().message};
  return success();
}

Result<std::string> ImageCache::encode_png(const image::Image& img, color::Transfer colour) {
  std::error_code ec;
  fs::create_directories(folder_, ec);
  const fs::path file = folder_ / ("made" + std::to_string(files_++) + ".png");
  image::WriteOptions options;
  options.colour = colour;
  options.type = image::SampleType::u8;
  if (Status s = image::write_image(img, file, options); !s) return s.error();
  std::ifstream in(file, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  fs::remove(file, ec);
  return bytes;
}

}  // namespace matbake::exporter
