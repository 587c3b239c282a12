#include "texture_files.hpp"

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

Result<const image::Image*> ImageCache::texture(int texture, color::Transfer colour) {
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
  if (const auto found = images_.find({source, colour}); found != images_.end()) return &found->second;
  auto bytes = gltf::image_bytes(doc_, std::size_t(source));
  if (!bytes) return bytes.error();
  const char* extension = extension_of(*bytes);
  if (!*extension) return Error{doc_.file, "image " + std::to_string(source) + " is not PNG, JPEG or WebP"};
  auto decoded = image::decode_image(as_bytes(*bytes), std::string("image") + extension, colour);
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
  // Decoded in full: a header that reads over truncated or corrupt pixels must not pass.
  auto decoded = image::decode_image(as_bytes(*bytes), std::string("image") + extension, color::Transfer::linear);
  if (!decoded) return Error{doc_.file, what + ": " + decoded.error().message};
  return success();
}

Result<std::string> ImageCache::encode_png(const image::Image& img, color::Transfer colour, image::SampleType type) const {
  image::WriteOptions options;
  options.colour = colour;
  options.type = type;
  options.png_level = encoding_.png_level;
  return image::encode_image(img, "made.png", options);
}

}  // namespace matbake::gltf
