#pragma once
// A glTF document's images decoded in memory through OIIO (each once per transfer), and images
// encoded as PNG bytes for the document's new files. No file is written outside the output.
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <utility>

#include "document.hpp"
#include "matbake/image.hpp"

namespace matbake::gltf {

// A channel of a decoded image read as RGBA: grey spreads to RGB, a missing alpha is 1.
float rgba(const image::Image& im, std::size_t pixel, int c);
// width × height × channels zeros.
image::Image blank(int width, int height, int channels);
// `im` resampled to width × height (itself when it has that size).
image::Image at_size(const image::Image& im, int width, int height);

// Names `name` in extensionsUsed, and in extensionsRequired too when `required` (each once).
void require_extension(Document& doc, const std::string& name, bool required);

// `name` with only the characters safe in a URI and a file name (letters, digits, _ and -): each run
// of others becomes one _, none at either end.
std::string uri_safe(const std::string& name);

// `name` + `extension`, or name_2, name_3... when a file of the document already has that URI.
std::string free_uri(const Document& doc, const std::string& name, const std::string& extension);

// What names the files made for material `index`: its name made uri_safe and cut to
// kMaterialFileName characters (a file name of a few of them and a map's stays within a file
// system's 255 bytes), else "material<index>".
constexpr std::size_t kMaterialFileName = 64;
std::string material_file_name(const Json& material, int index);

// The format of the images a cache makes: PNG, or lossless 8-bit WebP (the file then requires
// EXT_texture_webp).
enum class MadeFormat { png, webp };

class ImageCache {
 public:
  ImageCache(const gltf::Document& doc, const image::Encoding& encoding, MadeFormat made)
      : doc_(doc), encoding_(encoding), made_(made) {}
  ImageCache(const ImageCache&) = delete;
  ImageCache& operator=(const ImageCache&) = delete;

  // The image of texture `texture`, colour channels decoded with `colour` (alpha stays linear).
  Result<const image::Image*> texture(int texture, color::Transfer colour);
  // The same, decoded anew and not kept: safe from several threads while the document does not
  // change, for work that holds one texture at a time.
  Result<image::Image> decode(int texture, color::Transfer colour) const;
  std::size_t decoded() const { return images_.size(); }
  // Drops every decoded image kept (texture() decodes again when asked).
  void forget_decoded() { images_.clear(); }

  // Images [0, `count`) of the document that no decode of this cache has read: each a PNG, JPEG or
  // WebP that decodes in full (band by band, several at once, pixels not kept), or a KTX2 file
  // (passed through). The first bad one's error. Called once the work that decodes is done, so
  // that no image is decoded only to be checked.
  Status check_undecoded(std::size_t count) const;
  // The width and height of texture `texture`'s image, from its header.
  Result<std::pair<int, int>> size_of(int texture) const;

  // A new image of `doc` (the cache's document) holding `img`, its colour channels encoded with
  // `colour`, in the cache's format: a new file `<name>.png`, or `<name>.webp` (lossless,
  // 8-bit), which the file then requires EXT_texture_webp for. Returns the image's index and URI.
  struct Made {
    int index = -1;  // of the image, or of the texture (add_texture)
    std::string uri;
  };
  Result<Made> add_image(Document& doc, const image::Image& img, color::Transfer colour, const std::string& name,
                         image::SampleType type = image::SampleType::u8) const;
  // add_image's two steps: `img` as the cache's format's bytes (`name` names it in errors), and
  // those bytes as a new image of `doc`.
  Result<std::string> encode(const image::Image& img, color::Transfer colour, const std::string& name,
                             image::SampleType type = image::SampleType::u8) const;
  Made add_encoded(Document& doc, std::string bytes, const std::string& name) const;
  int png_level() const { return encoding_.png_level; }
  // A new texture over a new image (add_image), through EXT_texture_webp when WebP, with the
  // sampler of texture `sampler_from` (none when −1). Returns the texture's index and the image's URI.
  Result<Made> add_texture(Document& doc, const image::Image& img, color::Transfer colour, const std::string& name,
                           int sampler_from, image::SampleType type = image::SampleType::u8) const;
  bool webp() const { return made_ == MadeFormat::webp; }

 private:
  Result<int> source_of(int texture) const;
  Result<image::Image> decode_source(int source, color::Transfer colour) const;

  const gltf::Document& doc_;
  image::Encoding encoding_;
  MadeFormat made_;
  std::map<std::pair<int, color::Transfer>, image::Image> images_;  // by (image index, transfer)
  mutable std::mutex decoded_mutex_;
  mutable std::set<int> decoded_sources_;  // images a decode has read in full
};

}  // namespace matbake::gltf
