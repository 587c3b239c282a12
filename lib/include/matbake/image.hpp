#pragma once
// Images in memory are float, interleaved, linear (decoded at read, encoded at write) and keep
// alpha unassociated: OIIO is told so on both sides (../shared/design/DEBIAN-NOTES.md).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/color.hpp"
#include "matbake/enum_names.hpp"
#include "matbake/result.hpp"

namespace matbake::image {

enum class SampleType { u8, u16, half, f32 };

inline constexpr NameTable<SampleType, 4> kSampleTypeNames{
    {{SampleType::u8, "8"}, {SampleType::u16, "16"}, {SampleType::half, "half"}, {SampleType::f32, "float"}}};
inline std::string_view sample_type_name(SampleType type) { return name_in(kSampleTypeNames, type); }
// An image size as text: "1024" (square) or "2048x1024" (also "X"); any positive or not, the caller
// judges the range.
std::optional<std::pair<int, int>> size_from_text(std::string_view text);
bool is_integer(SampleType type);
// Why a file of `path`'s format cannot hold `type` samples ("PNG stores 8 or 16-bit samples, not
// half"), or nothing: PNG 8 or 16, EXR half or float, JPEG and WebP 8, TIFF any. Every writer
// refuses what this refuses, so no door can write half samples into an 8-bit file.
std::optional<std::string> sample_type_problem(const std::filesystem::path& path, SampleType type);

// The largest image matbake holds, in pixels (width × height), for every image it reads or makes:
// a size beyond it is refused before anything is allocated, so a 100-byte file that declares
// 100000 × 100000 costs nothing. Default 2^28 (16384 × 16384: up to 4 GiB as float RGBA). Process-wide,
// like OIIO's own limits; the CLI's --max-pixels sets it.
inline constexpr std::uint64_t kDefaultMaxPixels = std::uint64_t{1} << 28;
void set_max_pixels(std::uint64_t pixels);
std::uint64_t max_pixels();
// Refuses (naming `file`) a size of 0 or one beyond max_pixels().
Status check_image_size(const std::string& file, std::int64_t width, std::int64_t height);

// Size and channel layout of an image, without its pixels.
struct ImageLayout {
  int width = 0;
  int height = 0;
  int channels = 0;                        // 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA
  std::vector<std::string> channel_names;  // as stored ("R", "G", "B", "A", "Y", ...)
  int alpha_channel = -1;                  // index into channels, or -1

  std::size_t sample_count() const {
    return std::size_t(width) * std::size_t(height) * std::size_t(channels);
  }
};

struct Image : ImageLayout {
  std::vector<float> pixels;  // width * height * channels, row-major, interleaved
};

// Reserves room for `samples` in `pixels` (before they are written), in 2 MiB pages where the
// kernel allows: for every large image a module makes, so that filling it costs few page faults.
void reserve_pixels(std::vector<float>& pixels, std::size_t samples);

// Per-channel transfers: `colour` for colour channels, linear for alpha.
std::vector<color::Transfer> channel_transfers(const ImageLayout& layout, color::Transfer colour);

struct ReadInfo {
  SampleType stored_type = SampleType::u8;  // the closest of ours to what the file holds
  std::string format_name;                  // OIIO's names: "png", "openexr", "tiff", "jpeg", ...
  int width = 0, height = 0;                // as the header declares them
  int channels = 0;
  // The colour encoding the file declares: PNG cICP (transfer 13 sRGB, 8 linear, 4 gamma 2.2),
  // else an sRGB chunk or an iCCP profile named sRGB, else gAMA 1/2.2 or 1.0; EXR linear; TIFF
  // as OIIO reports it. Unset: untagged (or a tag matbake cannot interpret, e.g. another ICC profile).
  std::optional<color::Transfer> tagged;
  std::string tag;  // "sRGB chunk", "gAMA 1.0", "cICP transfer 13", "openexr", ...
};

// Reads any image OIIO can (PNG with libspng, other formats with OIIO, loaded on first need) and
// decodes colour channels with `colour` (alpha stays linear).
// Errors: missing or unreadable file, 0 or more than 4 channels, NaN or Inf samples (counted),
// and finite samples that overflow float when decoded.
Result<Image> read_image(const std::filesystem::path& path, color::Transfer colour,
                         ReadInfo* info = nullptr);

// Whether `path` can be read as an image file at all: it exists and is a regular file (not a
// folder, FIFO or device); read_image's first check, for readers that take the bytes themselves.
Status check_image_file(const std::filesystem::path& path);

// An image held in memory (a glTF's embedded PNG, say): `name`'s extension picks the reader, and
// names the image in errors. Same checks as read_image.
Result<Image> decode_image(std::span<const unsigned char> bytes, const std::filesystem::path& name,
                           color::Transfer colour, ReadInfo* info = nullptr);

// The layout of an image held in memory, from its header (and, for PNG, the chunks up to its first
// pixels): what decode_image would return, without decoding.
Result<ImageLayout> probe_image_bytes(std::span<const unsigned char> bytes, const std::filesystem::path& name);

// decode_image's checks without keeping the pixels: every row decoded through one band's buffer, so
// a header that reads over truncated or corrupt pixels fails here too. Its layout when it decodes.
Result<ImageLayout> check_image_bytes(std::span<const unsigned char> bytes, const std::filesystem::path& name);

// Opens the file's header only: what it stores, without reading pixels.
Result<ReadInfo> probe_image(const std::filesystem::path& path);

// PNG deflate effort, libdeflate's levels: 0 stores, 1 is fastest, 12 smallest. Measured on
// painted 2048² textures in docs/performance.md.
inline constexpr int kPngLevelFast = 1;
inline constexpr int kPngLevelDefault = 6;
inline constexpr int kPngLevelSmallest = 12;
// "fast", "default", "small" or a level "0" to "12".
std::optional<int> png_level_from_name(std::string_view name);

// How matbake encodes the images it writes, whichever command writes them (convert, pack, unpack,
// workflow, export, bake-ao's textures, a build): its parameters are image::encoding_params(). The
// format of a glTF's textures is delivery's (delivery::Options::texture_format).
struct Encoding {
  int png_level = kPngLevelDefault;  // 8/16-bit PNG deflate effort
};

struct WriteOptions {
  color::Transfer colour = color::Transfer::linear;  // applied to colour channels, never alpha
  SampleType type = SampleType::half;
  std::string compression;  // OIIO "compression" attribute; empty: "zip" for EXR, else default
  std::string colorspace;   // written as oiio:ColorSpace when not empty
  int png_level = kPngLevelDefault;  // 8/16-bit PNG (written by matbake, not OIIO)
};

// Writes atomically: a temporary file in the target folder, renamed over `path` when complete.
// The format follows the extension. Output bytes depend only on the inputs (no timestamps).
// Errors: unwritable folder, unknown extension, half output beyond the half range (±65504).
Status write_image(const Image& image, const std::filesystem::path& path, const WriteOptions& options);

// The bytes of `image` in the format of `name`'s extension (as write_image would write the file).
Result<std::string> encode_image(const Image& image, const std::filesystem::path& name, const WriteOptions& options);

// The bytes of an image of `layout` that is never held whole: `fill(y, rows, samples)` writes rows
// [y, y + rows) into `samples` (layout.channels a texel, row by row), for several bands at once.
using BandFill = std::function<void(int y, int rows, std::span<float> samples)>;
Result<std::string> encode_bands(const ImageLayout& layout, const BandFill& fill, const std::filesystem::path& name,
                                 const WriteOptions& options);

// Reads `input` and writes `output` band by band (rows), `transform` applied to each decoded band
// in between: reading, transforming and writing overlap on the cores, and memory stays a few bands
// whatever the image size. Same checks and guarantees as read_image and write_image.
struct BandTransform {
  std::function<Status(const ImageLayout&)> accept;  // once, before any band: may refuse the input
  std::function<void(std::span<float> band, const ImageLayout&)> apply;  // each band, in parallel
};
Status stream_image(const std::filesystem::path& input, color::Transfer decode, const std::filesystem::path& output,
                    const WriteOptions& options, const BandTransform& transform = {}, ReadInfo* info = nullptr,
                    ImageLayout* layout = nullptr);

// Resampled to width × height with OIIO's default filter for the direction (e.g. Lanczos 3 when
// shrinking), on the values as they are: pass linear data to filter in linear light.
Image resize_image(const Image& image, int width, int height);

// Threads OIIO may use (its EXR compressions other than none/zip/zips above all); 0: one per core.
// Applied when OIIO is loaded, if it is not yet.
void set_thread_count(int threads);

}  // namespace matbake::image
