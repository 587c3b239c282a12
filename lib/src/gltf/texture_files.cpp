#include "texture_files.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <set>

namespace matbake::gltf {
namespace {

// The extension OIIO picks its reader by, from the bytes' signature.
const char* extension_of(const std::string& bytes) {
  if (bytes.rfind("\x89PNG", 0) == 0) return ".png";
  if (bytes.rfind("\xff\xd8", 0) == 0) return ".jpg";
  if (bytes.size() > 12 && bytes.rfind("RIFF", 0) == 0 && bytes.compare(8, 4, "WEBP") == 0) return ".webp";
  return "";
}

constexpr int kOnlyKtx2 = -2;

// The image a texture's texels are read from: its core source (PNG or JPEG), else its
// EXT_texture_webp source; kOnlyKtx2 when it has only a KHR_texture_basisu one, −1 when none.
int decodable_source(const Json& texture) {
  const auto source_of = [](const Json& holder) { return integer_in<int>(holder, "source", -1, -1); };
  if (const int core = source_of(texture); core >= 0) return core;
  if (!texture.contains("extensions") || !texture["extensions"].is_object()) return -1;
  const Json& extensions = texture["extensions"];
  if (extensions.contains("EXT_texture_webp")) {
    if (const int webp = source_of(extensions["EXT_texture_webp"]); webp >= 0) return webp;
  }
  return extensions.contains("KHR_texture_basisu") ? kOnlyKtx2 : -1;
}

std::span<const unsigned char> as_bytes(const std::string& s) {
  return {reinterpret_cast<const unsigned char*>(s.data()), s.size()};
}

// Grey (and grey + alpha) spread to RGB (RGBA): WebP holds no one-channel image.
image::Image as_rgb(const image::Image& grey) {
  image::Image out;
  out.width = grey.width, out.height = grey.height, out.channels = grey.channels + 2;
  out.channel_names = out.channels == 4 ? std::vector<std::string>{"R", "G", "B", "A"} : std::vector<std::string>{"R", "G", "B"};
  out.alpha_channel = out.channels == 4 ? 3 : -1;
  const std::size_t pixels = std::size_t(grey.width) * std::size_t(grey.height);
  out.pixels.resize(pixels * std::size_t(out.channels));
  for (std::size_t p = 0; p < pixels; ++p) {
    for (int c = 0; c < out.channels; ++c) out.pixels[p * std::size_t(out.channels) + std::size_t(c)] = rgba(grey, p, c == 3 ? 3 : c);
  }
  return out;
}

}  // namespace

// A channel of a decoded image read as RGBA: grey spreads to RGB, a missing alpha is 1.
float rgba(const image::Image& im, std::size_t pixel, int c) {
  const std::size_t base = pixel * std::size_t(im.channels);
  if (c == 3) return im.channels == 4 ? im.pixels[base + 3] : im.channels == 2 ? im.pixels[base + 1] : 1.0f;
  return im.channels >= 3 ? im.pixels[base + std::size_t(c)] : im.pixels[base];
}

image::Image blank(int width, int height, int channels) {
  image::Image im;
  im.width = width, im.height = height, im.channels = channels;
  image::reserve_pixels(im.pixels, im.sample_count());
  im.pixels.assign(im.sample_count(), 0.0f);
  return im;
}

image::Image at_size(const image::Image& im, int width, int height) {
  return im.width == width && im.height == height ? im : image::resize_image(im, width, height);
}

// The image a texture's texels are read from, or why there is none.
Result<int> ImageCache::source_of(int texture) const {
  const gltf::Json& json = doc_.json;
  if (texture < 0 || !json.contains("textures") || std::size_t(texture) >= json["textures"].size()) {
    return Error{doc_.file, "texture " + std::to_string(texture) + " does not exist"};
  }
  const int source = decodable_source(json["textures"][std::size_t(texture)]);
  if (source < 0) {
    return Error{doc_.file, "/textures/" + std::to_string(texture) + ": " +
                                (source == kOnlyKtx2 ? "its only image is KTX2 (KHR_texture_basisu), which matbake cannot decode, "
                                                       "and this work needs its texels"
                                                     : "no PNG, JPEG or WebP image to read")};
  }
  return source;
}

Result<image::Image> ImageCache::decode_source(int source, color::Transfer colour) const {
  auto bytes = gltf::image_bytes(doc_, std::size_t(source));
  if (!bytes) return bytes.error();
  const char* extension = extension_of(*bytes);
  if (!*extension) return Error{doc_.file, "image " + std::to_string(source) + " is not PNG, JPEG or WebP"};
  auto decoded = image::decode_image(as_bytes(*bytes), std::string("image") + extension, colour);
  if (!decoded) return Error{doc_.file, "image " + std::to_string(source) + ": " + decoded.error().message};
  std::lock_guard lock(decoded_mutex_);
  decoded_sources_.insert(source);
  return decoded;
}

Result<const image::Image*> ImageCache::texture(int texture, color::Transfer colour) {
  auto source = source_of(texture);
  if (!source) return source.error();
  if (const auto found = images_.find({*source, colour}); found != images_.end()) return &found->second;
  auto decoded = decode_source(*source, colour);
  if (!decoded) return decoded.error();
  return &(images_[{*source, colour}] = std::move(*decoded));
}

Result<image::Image> ImageCache::decode(int texture, color::Transfer colour) const {
  auto source = source_of(texture);
  if (!source) return source.error();
  return decode_source(*source, colour);
}

Status ImageCache::check_undecoded(std::size_t count) const {
  count = std::min(count, array_in(doc_.json, "images").size());
  std::vector<Status> checked(count, success());
  tbb::parallel_for(std::size_t(0), count, [&](std::size_t index) {
    {
      std::lock_guard lock(decoded_mutex_);
      if (decoded_sources_.count(int(index))) return;
    }
    auto bytes = gltf::image_bytes(doc_, index);
    const std::string what = "image " + std::to_string(index);
    if (!bytes) {
      checked[index] = bytes.error();
    } else if (bytes->rfind("\xabKTX 20\xbb", 0) == 0) {
      return;  // passed through
    } else if (const char* extension = extension_of(*bytes); !*extension) {
      checked[index] = Error{doc_.file, what + " is not PNG, JPEG, WebP or KTX2"};
    } else if (auto layout = image::check_image_bytes(as_bytes(*bytes), std::string("image") + extension); !layout) {
      checked[index] = Error{doc_.file, what + ": " + layout.error().message};
    }
  }, tbb::simple_partitioner());
  for (Status& s : checked) {
    if (!s) return s.error();
  }
  return success();
}

Result<std::pair<int, int>> ImageCache::size_of(int texture) const {
  auto source = source_of(texture);
  if (!source) return source.error();
  auto bytes = gltf::image_bytes(doc_, std::size_t(*source));
  if (!bytes) return bytes.error();
  const char* extension = extension_of(*bytes);
  if (!*extension) return Error{doc_.file, "image " + std::to_string(*source) + " is not PNG, JPEG or WebP"};
  auto layout = image::probe_image_bytes(as_bytes(*bytes), std::string("image") + extension);
  if (!layout) return Error{doc_.file, "image " + std::to_string(*source) + ": " + layout.error().message};
  return std::pair{layout->width, layout->height};
}

Result<std::string> ImageCache::encode(const image::Image& img, color::Transfer colour, const std::string& name,
                                       image::SampleType type) const {
  if (webp() && type != image::SampleType::u8) {
    return Error{doc_.file, name + ": WebP holds 8 bits per channel; write 16-bit textures as PNG (" + mention("texture_format", "png") + ")"};
  }
  image::WriteOptions options;
  options.colour = colour;
  options.type = type;
  options.png_level = encoding_.png_level;
  if (webp()) options.compression = "lossless";  // data (occlusion, roughness) survives as written
  return image::encode_image(webp() && img.channels < 3 ? as_rgb(img) : img, name + (webp() ? ".webp" : ".png"), options);
}

ImageCache::Made ImageCache::add_encoded(Document& doc, std::string bytes, const std::string& name) const {
  Made made;
  made.uri = free_uri(doc, name, webp() ? ".webp" : ".png");
  doc.new_files[made.uri] = std::move(bytes);
  doc.json["images"].push_back({{"uri", made.uri},
                                {"mimeType", webp() ? "image/webp" : "image/png"},
                                {"name", made.uri.substr(0, made.uri.rfind('.'))}});
  made.index = int(doc.json["images"].size()) - 1;
  if (webp()) require_extension(doc, "EXT_texture_webp", true);
  return made;
}

Result<ImageCache::Made> ImageCache::add_image(Document& doc, const image::Image& img, color::Transfer colour,
                                               const std::string& name, image::SampleType type) const {
  auto bytes = encode(img, colour, name, type);
  if (!bytes) return bytes.error();
  return add_encoded(doc, std::move(*bytes), name);
}

Result<ImageCache::Made> ImageCache::add_texture(Document& doc, const image::Image& img, color::Transfer colour,
                                                 const std::string& name, int sampler_from, image::SampleType type) const {
  auto made = add_image(doc, img, colour, name, type);
  if (!made) return made.error();
  Json texture = webp() ? Json{{"extensions", {{"EXT_texture_webp", {{"source", made->index}}}}}} : Json{{"source", made->index}};
  texture["name"] = doc.json["images"][std::size_t(made->index)]["name"];
  if (sampler_from >= 0 && doc.json["textures"][std::size_t(sampler_from)].contains("sampler")) {
    texture["sampler"] = doc.json["textures"][std::size_t(sampler_from)]["sampler"];
  }
  doc.json["textures"].push_back(std::move(texture));
  made->index = int(doc.json["textures"].size()) - 1;
  return made;
}

void require_extension(Document& doc, const std::string& name, bool required) {
  for (const std::string_view list : {"extensionsUsed", "extensionsRequired"}) {
    if (list == "extensionsRequired" && !required) continue;
    Json& names = doc.json[std::string(list)];
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  }
}

std::string uri_safe(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const bool safe = std::isalnum((unsigned char)c) || c == '_' || c == '-';
    if (safe) out += c;
    else if (!out.empty() && out.back() != '_') out += '_';  // "Paint (crate 2)" → Paint_crate_2
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

std::string free_uri(const Document& doc, const std::string& name, const std::string& extension) {
  std::set<std::string> taken;
  for (const auto& [uri, bytes] : doc.new_files) taken.insert(uri);
  for (const auto& [file, bytes] : doc.beside) taken.insert(file);
  for (const Json& img : array_in(doc.json, "images")) {
    if (img.contains("uri") && img["uri"].is_string()) taken.insert(decode_uri(img["uri"].get<std::string>()));
  }
  std::string uri = name + extension;
  for (int n = 2; taken.count(uri); ++n) uri = name + "_" + std::to_string(n) + extension;
  return uri;
}

std::string material_file_name(const Json& material, int index) {
  std::string name = uri_safe(name_in(material, "")).substr(0, kMaterialFileName);
  while (!name.empty() && name.back() == '_') name.pop_back();
  return name.empty() ? "material" + std::to_string(index) : name;
}

}  // namespace matbake::gltf
