// All image file I/O goes through here. Reading and writing work in bands of rows (RowReader,
// RowWriter); whole-image reads and writes are one band. PNG (read and 8/16-bit written) and
// scanline EXR written as half or float (none, zip, zips) are matbake's own codecs; every other
// format is OpenImageIO's, from the module loaded on first need (oiio_module.hpp).
#include <tbb/parallel_pipeline.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "matbake/atomic_file.hpp"
#include "matbake/image.hpp"
#include "matbake/pixels.hpp"
#include "exr_encode.hpp"
#include "oiio_module.hpp"
#include "png_decode.hpp"
#include "png_encode.hpp"

namespace fs = std::filesystem;

namespace matbake::image {
namespace {

std::atomic<std::uint64_t> g_max_pixels{kDefaultMaxPixels};

// Non-finite samples, counted, and where the first one is (its sample index in the file).
struct NonFinite {
  std::size_t nan = 0;
  std::size_t inf = 0;
  std::size_t first = SIZE_MAX;
  bool any() const { return nan + inf > 0; }
  void add(bool is_nan, bool is_inf, std::size_t index) {
    nan += is_nan;
    inf += is_inf;
    if ((is_nan || is_inf) && index < first) first = index;
  }
};

void count_float(std::span<const float> samples, std::size_t first_index, NonFinite& n) {
  for (std::size_t i = 0; i < samples.size(); ++i) n.add(std::isnan(samples[i]), std::isinf(samples[i]), first_index + i);
}

void count_half(std::span<const uint16_t> bits, std::size_t first_index, NonFinite& n) {
  constexpr uint16_t kExponent = 0x7c00, kMantissa = 0x03ff;  // all-ones exponent: Inf or NaN
  for (std::size_t i = 0; i < bits.size(); ++i) {
    const bool special = (bits[i] & kExponent) == kExponent;
    n.add(special && (bits[i] & kMantissa) != 0, special && (bits[i] & kMantissa) == 0, first_index + i);
  }
}

Result<std::unique_ptr<StoredReader>> open_with_oiio(const fs::path& path, std::span<const unsigned char> memory) {
  auto oiio = oiio_codecs(path.string());
  if (!oiio) return oiio.error();
  return (*oiio)->open_reader(path, memory);
}

// Decodes bands of rows in order. Non-finite samples are bad input and finite ones the decode
// overflows (sRGB/gamma 2.2 of values above about 1e16) are too; both are counted over the whole
// file, so the error gives the totals, and reported by finish().
class RowReader {
 public:
  static Result<RowReader> open(const fs::path& path, color::Transfer colour) {
    if (Status s = check_image_file(path); !s) return s.error();
    unsigned char start[8] = {};
    std::ifstream(path, std::ios::binary).read(reinterpret_cast<char*>(start), sizeof start);
    return open(path, colour, start, {});
  }

  // An image in memory: `name` names it (and its extension is OIIO's first guess); `bytes` must
  // outlive the reader.
  static Result<RowReader> open_memory(std::span<const unsigned char> bytes, const fs::path& name, color::Transfer colour) {
    if (bytes.empty()) return Error{name.string(), "not a readable image: empty"};
    return open(name, colour, bytes, bytes);
  }

 private:
  // PNG by its signature, whatever the name; everything else by OIIO.
  static Result<RowReader> open(const fs::path& path, color::Transfer colour, std::span<const unsigned char> start,
                                std::span<const unsigned char> memory) {
    auto stored = has_png_signature(start) ? open_png(path.string(), memory) : open_with_oiio(path, memory);
    if (!stored) return stored.error();
    const ImageLayout& layout = (*stored)->format().layout;
    if (layout.channels < 1 || layout.channels > 4) {
      return Error{path.string(), std::to_string(layout.channels) +
                                      " channels; matbake reads 1 to 4 (gray, gray+alpha, RGB, RGBA)"};
    }
    if (Status s = check_image_size(path.string(), layout.width, layout.height); !s) return s.error();
    return RowReader(path, std::move(*stored), colour);
  }

 public:
  const ImageLayout& layout() const { return stored_->format().layout; }
  ReadInfo info() const {
    const StoredFormat& f = stored_->format();
    return {f.stored, f.format_name, layout().width, layout().height, layout().channels, f.tagged, f.tag};
  }

  // Rows [y, y + rows) into `out`, decoded.
  Status read_rows(int y, int rows, std::span<float> out) {
    switch (stored_->format().stored) {
      case SampleType::u8: return read_and_decode<uint8_t>(y, rows, out);
      case SampleType::u16: return read_and_decode<uint16_t>(y, rows, out);
      case SampleType::half: return read_and_decode<uint16_t>(y, rows, out);  // bit patterns
      case SampleType::f32: return read_and_decode<float>(y, rows, out);
    }
    return success();
  }

  Status finish() const {
    if (bad_.any()) {
      const std::size_t channels = std::size_t(layout().channels), row = std::size_t(layout().width) * channels;
      const std::size_t x = bad_.first % row / channels, y = bad_.first / row, c = bad_.first % channels;
      return Error{path_.string(), "contains " + std::to_string(bad_.nan) + " NaN and " + std::to_string(bad_.inf) +
                                       " Inf samples (the first at x " + std::to_string(x) + ", y " +
                                       std::to_string(y) + ", channel " + std::to_string(c) +
                                       "); matbake rejects non-finite texels"};
    }
    if (overflow_ > 0) {
      return Error{path_.string(), std::to_string(overflow_) + " samples overflow float when decoded from " +
                                       std::string(color::transfer_name(colour_)) + " (inputs above about 1e16)"};
    }
    return success();
  }

  bool failed() const { return bad_.any() || overflow_ > 0; }

 private:
  RowReader(fs::path path, std::unique_ptr<StoredReader> stored, color::Transfer colour)
      : path_(std::move(path)), stored_(std::move(stored)), colour_(colour),
        transfers_(channel_transfers(stored_->format().layout, colour)) {}

  template <class T>
  Status read_and_decode(int y, int rows, std::span<float> out) {
    raw_.resize(out.size() * sizeof(T));
    T* samples = reinterpret_cast<T*>(raw_.data());
    if (Status s = stored_->read(y, rows, samples); !s) return s;
    const std::span<const T> in(samples, out.size());
    const std::size_t first_index = std::size_t(y) * std::size_t(layout().width) * std::size_t(layout().channels);
    if constexpr (std::is_same_v<T, float>) {
      count_float(in, first_index, bad_);
      color::decode_pixels(in, out, transfers_);
    } else if constexpr (std::is_same_v<T, uint16_t>) {
      if (stored_->format().stored == SampleType::half) {
        count_half(in, first_index, bad_);
        color::decode_half_pixels(in, out, transfers_);
      } else {
        color::decode_pixels(in, out, transfers_);
      }
    } else {
      color::decode_pixels(in, out, transfers_);
    }
    if (colour_ != color::Transfer::linear && !bad_.any()) {
      overflow_ += std::size_t(std::count_if(out.begin(), out.end(), [](float v) { return std::isinf(v); }));
    }
    return success();
  }

  fs::path path_;
  std::unique_ptr<StoredReader> stored_;
  color::Transfer colour_;
  std::vector<color::Transfer> transfers_;
  std::vector<std::byte> raw_;
  NonFinite bad_;
  std::size_t overflow_ = 0;
};

// `extension` in lower case, with its dot.
bool has_extension(const fs::path& path, std::string_view extension) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == extension;
}

// A band of rows encoded for the file: samples as stored (PNG, OIIO's formats) or, for the EXR
// that matbake writes, its chunks.
struct EncodedBand {
  int y = 0;
  int rows = 0;
  std::vector<std::byte> samples;
  std::vector<ExrChunk> chunks;
  std::size_t beyond_half = 0;  // samples that half cannot hold
};

// Encodes and writes bands of rows in order into a temporary file; commit() renames it over the
// target. 8- and 16-bit PNG goes through our PngEncoder (libdeflate), scanline EXR (half or float;
// none, zip or zips) through our ExrEncoder, every other format through OIIO. Bands may be encoded
// in parallel (encode_rows) and are written in order (write_band). Half output beyond the half
// range is refused (it would round to Inf), counted over all bands.
class RowWriter {
 public:
  static Result<RowWriter> open(const fs::path& path, const ImageLayout& layout, const WriteOptions& options) {
    if (auto problem = sample_type_problem(path, options.type)) return Error{path.string(), *problem, true};
    auto file = AtomicFile::create(path);
    if (!file) return file.error();
    const fs::path temp = file->temp_path();  // copied: the file is moved in the same call
    return open(path, temp, std::move(*file), nullptr, layout, options);
  }

  // Into `bytes`: `name`'s extension picks the writer.
  static Result<RowWriter> open_memory(std::vector<unsigned char>& bytes, const fs::path& name, const ImageLayout& layout,
                                       const WriteOptions& options) {
    if (auto problem = sample_type_problem(name, options.type)) return Error{name.string(), *problem, true};
    return open(name, name, std::nullopt, &bytes, layout, options);
  }

 private:
  static Result<RowWriter> open(const fs::path& path, const fs::path& written, std::optional<AtomicFile> file,
                                std::vector<unsigned char>* memory, const ImageLayout& layout, const WriteOptions& options) {
    if (options.png_level < 0 || options.png_level > kPngLevelSmallest) {
      return Error{path.string(), "PNG compression level " + std::to_string(options.png_level) + " is not 0 to 12"};
    }
    RowWriter writer(path, written, std::move(file), memory, layout, options);
    if (has_extension(written, ".png") && is_integer(options.type)) {
      writer.png_ = std::make_unique<PngEncoder>(layout, options.type == SampleType::u8 ? 8 : 16, options.png_level,
                                                 options.colorspace);
      return writer;
    }
    const bool exr = has_extension(written, ".exr");
    const auto exr_compression = exr_compression_from_name(options.compression.empty() ? "zip" : options.compression);
    if (exr && !is_integer(options.type) && exr_compression) {
      ImageLayout named = layout;  // unnamed channels get OIIO's names, as OIIO would write them
      if (named.channel_names.size() != std::size_t(layout.channels)) {
        named.channel_names = default_channel_names(layout.channels);
      }
      auto encoder = ExrEncoder::open(written, path.string(), memory, named, options.type, *exr_compression,
                                      options.colorspace);
      if (!encoder) return encoder.error();
      writer.exr_ = std::make_unique<ExrEncoder>(std::move(*encoder));
      return writer;
    }
    auto oiio = oiio_codecs(path.string());
    if (!oiio) return oiio.error();
    auto other = (*oiio)->open_writer(path, written, memory, layout, options);
    if (!other) return other.error();
    writer.other_ = std::move(*other);
    return writer;
  }

 public:
  // The first row of every band but the last is a multiple of this (EXR's chunks).
  int band_alignment() const { return exr_ ? exr_->chunk_rows() : 1; }

  // Into `band` (its storage reused). Thread-safe: bands may be encoded in parallel.
  void encode_rows(int y, int rows, std::span<const float> pixels, EncodedBand& band) const {
    band.y = y;
    band.rows = rows;
    band.beyond_half = 0;
    switch (options_.type) {
      case SampleType::u8: encode_samples<uint8_t>(pixels, band); break;
      case SampleType::u16: encode_samples<uint16_t>(pixels, band); break;
      case SampleType::half:
      case SampleType::f32: encode_samples<float>(pixels, band); break;  // to half when written, nearest even
    }
    if (exr_ && band.beyond_half == 0) {
      exr_->encode(y, rows, {reinterpret_cast<const float*>(band.samples.data()), pixels.size()}, band.chunks);
    }
  }

  // In order of rows.
  Status write_band(const EncodedBand& band) {
    beyond_half_ += band.beyond_half;
    if (beyond_half_ > 0) return success();  // keep counting; commit() refuses
    if (exr_) return exr_->write(band.chunks);
    switch (options_.type) {
      case SampleType::u8: return write_samples<uint8_t>(band);
      case SampleType::u16: return write_samples<uint16_t>(band);
      case SampleType::half:
      case SampleType::f32: return write_samples<float>(band);
    }
    return success();
  }

  Status commit() {
    if (beyond_half_ > 0) {
      return Error{path_.string(),
                   std::to_string(beyond_half_) + " samples exceed the half-float range (65504); use float samples"};
    }
    if (png_) {
      const std::string bytes = png_->finish();
      if (memory_) {
        memory_->assign(bytes.begin(), bytes.end());
        return success();
      }
      std::ofstream file(written_, std::ios::binary | std::ios::trunc);
      file.write(bytes.data(), std::streamsize(bytes.size()));
      file.close();
      if (!file) return Error{path_.string(), "cannot write (disk full or not writable?)"};
    } else if (exr_) {
      if (Status s = exr_->finish(); !s) return s;
    } else if (Status s = other_->close(); !s) {
      return s;
    }
    return file_ ? file_->commit() : success();
  }

 private:
  RowWriter(fs::path path, fs::path written, std::optional<AtomicFile> file, std::vector<unsigned char>* memory,
            const ImageLayout& layout, const WriteOptions& options)
      : path_(std::move(path)), written_(std::move(written)), file_(std::move(file)), memory_(memory), options_(options),
        transfers_(channel_transfers(layout, options.colour)) {}

  template <class T>
  void encode_samples(std::span<const float> pixels, EncodedBand& band) const {
    band.samples.resize(pixels.size() * sizeof(T));
    const std::span<T> samples(reinterpret_cast<T*>(band.samples.data()), pixels.size());
    color::encode_pixels(pixels, samples, transfers_);
    if constexpr (std::is_same_v<T, float>) {
      if (options_.type == SampleType::half) {
        constexpr float kHalfOverflow = 65520.0f;  // from here on, rounding to half gives Inf
        band.beyond_half = std::size_t(
            std::count_if(samples.begin(), samples.end(), [](float v) { return std::abs(v) >= kHalfOverflow; }));
      }
    }
  }

  template <class T>
  Status write_samples(const EncodedBand& band) {
    const std::span<const T> samples(reinterpret_cast<const T*>(band.samples.data()), band.samples.size() / sizeof(T));
    if constexpr (!std::is_same_v<T, float>) {
      if (png_) {
        png_->add_rows(samples);
        return success();
      }
    }
    const SampleType type = std::is_same_v<T, uint8_t> ? SampleType::u8 : std::is_same_v<T, uint16_t> ? SampleType::u16 : SampleType::f32;
    return other_->write(band.y, band.rows, type, samples.data());
  }

  fs::path path_;
  fs::path written_;                  // the temporary file (or, in memory, the name)
  std::optional<AtomicFile> file_;    // none when writing to memory
  std::vector<unsigned char>* memory_ = nullptr;
  std::unique_ptr<StoredWriter> other_;  // every other format: OIIO's
  std::unique_ptr<PngEncoder> png_;      // 8/16-bit PNG
  std::unique_ptr<ExrEncoder> exr_;      // scanline EXR: half or float, none/zip/zips
  WriteOptions options_;
  std::vector<color::Transfer> transfers_;
  std::size_t beyond_half_ = 0;
};

// Rows per band: two of the 16-scanline chunks OpenEXR's zip compresses together, so each write
// compresses in parallel while the next band is read. Measured on a 2048x2048 RGBA PNG -> half
// zip EXR, 2 cores: 16 rows 1.28 s, 32 rows 0.81 s, 64 rows 0.90 s, 256 rows 0.95 s.
constexpr int kBandRows = 32;

// Rows per band read: about a million samples, few calls into OIIO.
int read_band_rows(std::size_t row_samples) { return int(std::max<std::size_t>(kBandRows, (std::size_t{1} << 20) / row_samples)); }

Result<Image> read_whole(RowReader& reader, ReadInfo* info) {
  if (info != nullptr) *info = reader.info();
  Image image;
  static_cast<ImageLayout&>(image) = reader.layout();
  // Reserved (address space only) and filled band by band: a file that declares more rows than it
  // holds fails at the first missing one, before the rest of its size is touched.
  reserve_pixels(image.pixels, image.sample_count());
  const std::size_t row_samples = std::size_t(image.width) * std::size_t(image.channels);
  const int band_rows = read_band_rows(row_samples);
  for (int y = 0; y < image.height; y += band_rows) {
    const int rows = std::min(band_rows, image.height - y);
    image.pixels.resize(image.pixels.size() + row_samples * std::size_t(rows));
    const std::span band(image.pixels.data() + row_samples * std::size_t(y), row_samples * std::size_t(rows));
    if (Status s = reader.read_rows(y, rows, band); !s) return s.error();
  }
  if (Status s = reader.finish(); !s) return s.error();
  return image;
}

// A band of rows on its way to the writer.
struct Band {
  int y = 0;
  int rows = 0;
  std::vector<float> pixels;     // the band's own pixels, when decoded into it (stream_image)
  std::span<const float> view;   // the pixels to encode: `pixels` or rows of a whole image
  EncodedBand encoded;
};

// Bands through `writer`: `next` (called in order, one call at a time) fills each band's rows and
// pixels and returns false after the last; `prepare` (a transform) and the encoding run on several
// bands at once, and the bands are written in order, so decoding, transforming and compressing
// overlap on the cores. The bands' buffers go round (a written band is the next one filled): fresh
// pages cost more than a fast deflate. Once `stop` is set nothing more is prepared, encoded or
// written. Returns the first write error.
Status write_bands(RowWriter& writer, const std::function<bool(Band&)>& next, const std::function<void(Band&)>& prepare,
                   std::atomic<bool>& stop) {
  std::optional<Error> write_error;
  std::mutex spare_mutex;
  std::vector<std::shared_ptr<Band>> spare;
  const std::size_t tokens = 2 * std::max(1u, std::thread::hardware_concurrency());
  tbb::parallel_pipeline(
      tokens,
      tbb::make_filter<void, std::shared_ptr<Band>>(tbb::filter_mode::serial_in_order,
                                                    [&](tbb::flow_control& fc) -> std::shared_ptr<Band> {
                                                      std::shared_ptr<Band> band;
                                                      {
                                                        std::lock_guard lock(spare_mutex);
                                                        if (!spare.empty()) {
                                                          band = std::move(spare.back());
                                                          spare.pop_back();
                                                        }
                                                      }
                                                      if (!band) band = std::make_shared<Band>();
                                                      if (!next(*band)) {
                                                        fc.stop();
                                                        return nullptr;
                                                      }
                                                      return band;
                                                    }) &
          tbb::make_filter<std::shared_ptr<Band>, std::shared_ptr<Band>>(
              tbb::filter_mode::parallel,
              [&](std::shared_ptr<Band> band) {
                if (stop) return band;
                if (prepare) prepare(*band);
                writer.encode_rows(band->y, band->rows, band->view, band->encoded);
                return band;
              }) &
          tbb::make_filter<std::shared_ptr<Band>, void>(tbb::filter_mode::serial_in_order, [&](std::shared_ptr<Band> band) {
            if (!stop) {
              if (Status s = writer.write_band(band->encoded); !s) {
                write_error = s.error();
                stop = true;
              }
            }
            std::lock_guard lock(spare_mutex);
            spare.push_back(std::move(band));
          }));
  if (write_error) return *write_error;
  return success();
}

// `rows` rounded up to a multiple of the writer's alignment (EXR chunks).
int aligned_band_rows(const RowWriter& writer, std::size_t rows) {
  const std::size_t alignment = std::size_t(writer.band_alignment());
  return int((rows + alignment - 1) / alignment * alignment);
}

// The next band of at most `band_rows` rows from `next_row` of an image `height` rows tall, advancing
// `next_row`; false past the last row.
bool cut_band(Band& band, int& next_row, int height, int band_rows) {
  if (next_row >= height) return false;
  band.y = next_row;
  band.rows = std::min(band_rows, height - next_row);
  next_row += band.rows;
  return true;
}

Status write_whole(RowWriter& writer, const Image& image) {
  if (image.channels < 1 || image.channels > 4 || image.pixels.size() != image.sample_count()) {
    return Error{"", "internal: inconsistent image"};
  }
  // In bands, so the encoded samples of a few bands are all the writer holds (and stay in cache).
  const std::size_t row_samples = std::size_t(image.width) * std::size_t(image.channels);
  const int band_rows = aligned_band_rows(writer, std::max<std::size_t>(kBandRows, (std::size_t{1} << 18) / row_samples));
  int next_row = 0;
  std::atomic<bool> stop{false};
  const auto next = [&](Band& band) {
    if (!cut_band(band, next_row, image.height, band_rows)) return false;
    band.view = {image.pixels.data() + row_samples * std::size_t(band.y), row_samples * std::size_t(band.rows)};
    return true;
  };
  if (Status s = write_bands(writer, next, {}, stop); !s) return s;
  return writer.commit();
}

}  // namespace

void set_max_pixels(std::uint64_t pixels) { g_max_pixels = pixels; }
std::uint64_t max_pixels() { return g_max_pixels; }

Status check_image_size(const std::string& file, std::int64_t width, std::int64_t height) {
  if (width <= 0 || height <= 0) {
    return Error{file, "declares a size of " + std::to_string(width) + "x" + std::to_string(height)};
  }
  const std::uint64_t limit = max_pixels();
  // width ≤ limit first, so the product cannot overflow.
  if (std::uint64_t(width) > limit || std::uint64_t(height) > limit / std::uint64_t(width)) {
    return Error{file, std::to_string(width) + "x" + std::to_string(height) + " is more than the limit of " +
                           std::to_string(limit) + " pixels (" + mention("max_pixels") + " raises it)"};
  }
  return success();
}

std::optional<std::pair<int, int>> size_from_text(std::string_view text) {
  const auto number = [](std::string_view digits) -> std::optional<int> {
    int value = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error != std::errc() || end != digits.data() + digits.size() || digits.empty()) return std::nullopt;
    return value;
  };
  const std::size_t x = text.find_first_of("xX");
  const auto width = number(text.substr(0, x));
  const auto height = x == std::string_view::npos ? width : number(text.substr(x + 1));
  if (!width || !height) return std::nullopt;
  return std::pair{*width, *height};
}

std::optional<int> png_level_from_name(std::string_view name) {
  if (name == "fast") return kPngLevelFast;
  if (name == "default") return kPngLevelDefault;
  if (name == "small") return kPngLevelSmallest;
  int level = -1;
  const auto [end, ec] = std::from_chars(name.data(), name.data() + name.size(), level);
  if (ec != std::errc() || end != name.data() + name.size() || level < 0 || level > kPngLevelSmallest) return std::nullopt;
  return level;
}

bool is_integer(SampleType type) { return type == SampleType::u8 || type == SampleType::u16; }

std::optional<std::string> sample_type_problem(const fs::path& path, SampleType type) {
  struct Stores {
    std::string_view extension, format;
    std::initializer_list<SampleType> types;
    std::string_view types_text;
  };
  static const Stores kFormats[] = {
      {".png", "PNG", {SampleType::u8, SampleType::u16}, "8 or 16-bit"},
      {".exr", "EXR", {SampleType::half, SampleType::f32}, "half or float"},
      {".jpg", "JPEG", {SampleType::u8}, "8-bit"},
      {".jpeg", "JPEG", {SampleType::u8}, "8-bit"},
      {".webp", "WebP", {SampleType::u8}, "8-bit"},
  };
  for (const Stores& f : kFormats) {
    if (!has_extension(path, f.extension)) continue;
    if (std::find(f.types.begin(), f.types.end(), type) != f.types.end()) return std::nullopt;
    return std::string(f.format) + " stores " + std::string(f.types_text) + " samples, not " +
           std::string(sample_type_name(type));
  }
  return std::nullopt;
}

std::vector<color::Transfer> channel_transfers(const ImageLayout& layout, color::Transfer colour) {
  std::vector<color::Transfer> transfers(std::size_t(layout.channels), colour);
  if (layout.alpha_channel >= 0 && layout.alpha_channel < layout.channels) {
    transfers[layout.alpha_channel] = color::Transfer::linear;
  }
  return transfers;
}

std::vector<std::string> default_channel_names(int channels) {
  if (channels == 1) return {"Y"};
  static const char* const kNames[] = {"R", "G", "B", "A"};
  return {kNames, kNames + std::min(channels, 4)};
}

Status check_image_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Error{path.string(), "no such file"};
  if (fs::is_directory(path, ec)) return Error{path.string(), "is a folder, not an image"};
  // A FIFO or a device (/dev/zero) never ends: only regular files are read.
  if (!fs::is_regular_file(path, ec)) return Error{path.string(), "is not a regular file"};
  return success();
}

Result<ReadInfo> probe_image(const fs::path& path) {
  return guarded(path.string(), [&]() -> Result<ReadInfo> {
    auto reader = RowReader::open(path, color::Transfer::linear);
    if (!reader) return reader.error();
    return reader->info();
  });
}

Result<Image> read_image(const fs::path& path, color::Transfer colour, ReadInfo* info) {
  return guarded(path.string(), [&]() -> Result<Image> {
    auto reader = RowReader::open(path, colour);
    if (!reader) return reader.error();
    return read_whole(*reader, info);
  });
}

Result<Image> decode_image(std::span<const unsigned char> bytes, const fs::path& name, color::Transfer colour,
                           ReadInfo* info) {
  return guarded(name.string(), [&]() -> Result<Image> {
    auto reader = RowReader::open_memory(bytes, name, colour);
    if (!reader) return reader.error();
    return read_whole(*reader, info);
  });
}

Result<ImageLayout> probe_image_bytes(std::span<const unsigned char> bytes, const fs::path& name) {
  return guarded(name.string(), [&]() -> Result<ImageLayout> {
    auto reader = RowReader::open_memory(bytes, name, color::Transfer::linear);
    if (!reader) return reader.error();
    return reader->layout();
  });
}

Result<ImageLayout> check_image_bytes(std::span<const unsigned char> bytes, const fs::path& name) {
  return guarded(name.string(), [&]() -> Result<ImageLayout> {
    auto reader = RowReader::open_memory(bytes, name, color::Transfer::linear);
    if (!reader) return reader.error();
    const ImageLayout layout = reader->layout();
    const std::size_t row_samples = std::size_t(layout.width) * std::size_t(layout.channels);
    const int band_rows = read_band_rows(row_samples);
    std::vector<float> band;
    for (int y = 0; y < layout.height; y += band_rows) {
      const int rows = std::min(band_rows, layout.height - y);
      band.resize(row_samples * std::size_t(rows));
      if (Status s = reader->read_rows(y, rows, band); !s) return s.error();
    }
    if (Status s = reader->finish(); !s) return s.error();
    return layout;
  });
}

Result<std::string> encode_image(const Image& image, const fs::path& name, const WriteOptions& options) {
  return guarded(name.string(), [&]() -> Result<std::string> {
    std::vector<unsigned char> bytes;
    {
      auto writer = RowWriter::open_memory(bytes, name, image, options);
      if (!writer) return writer.error();
      if (Status s = write_whole(*writer, image); !s) return s.error();
    }
    return std::string(bytes.begin(), bytes.end());
  });
}

Result<std::string> encode_bands(const ImageLayout& layout, const BandFill& fill, const fs::path& name, const WriteOptions& options) {
  return guarded(name.string(), [&]() -> Result<std::string> {
    if (layout.channels < 1 || layout.channels > 4 || layout.width < 1 || layout.height < 1) {
      return Error{name.string(), "internal: inconsistent image"};
    }
    std::vector<unsigned char> bytes;
    {
      auto writer = RowWriter::open_memory(bytes, name, layout, options);
      if (!writer) return writer.error();
      const std::size_t row_samples = std::size_t(layout.width) * std::size_t(layout.channels);
      const int band_rows = aligned_band_rows(*writer, std::max<std::size_t>(kBandRows, (std::size_t{1} << 18) / row_samples));
      int next_row = 0;
      std::atomic<bool> stop{false};
      const auto next = [&](Band& band) {
        if (!cut_band(band, next_row, layout.height, band_rows)) return false;
        band.pixels.resize(row_samples * std::size_t(band.rows));
        band.view = band.pixels;
        return true;
      };
      const auto prepare = [&](Band& band) { fill(band.y, band.rows, band.pixels); };
      if (Status s = write_bands(*writer, next, prepare, stop); !s) return s.error();
      if (Status s = writer->commit(); !s) return s.error();
    }
    return std::string(bytes.begin(), bytes.end());
  });
}

Status write_image(const Image& image, const fs::path& path, const WriteOptions& options) {
  return guarded(path.string(), [&]() -> Status {
    if (image.channels < 1 || image.channels > 4 || image.pixels.size() != image.sample_count()) {
      return Error{path.string(), "internal: inconsistent image"};
    }
    auto writer = RowWriter::open(path, image, options);
    if (!writer) return writer.error();
    return write_whole(*writer, image);
  });
}

Status stream_image(const fs::path& input, color::Transfer decode, const fs::path& output, const WriteOptions& options,
                    const BandTransform& transform, ReadInfo* info, ImageLayout* layout_out) {
  return guarded(input.string(), [&]() -> Status {
    auto reader = RowReader::open(input, decode);
    if (!reader) return reader.error();
    const ImageLayout& layout = reader->layout();
    if (info != nullptr) *info = reader->info();
    if (layout_out != nullptr) *layout_out = layout;
    if (transform.accept) {
      if (Status s = transform.accept(layout); !s) return s;
    }
    auto writer = RowWriter::open(output, layout, options);
    if (!writer) return writer.error();

    // After bad input the rest is still read (so the error counts it all) but nothing more is
    // transformed or written.
    std::optional<Error> read_error;
    std::atomic<bool> stop{false};
    int next_row = 0;
    const std::size_t row_samples = std::size_t(layout.width) * layout.channels;
    const int band_rows = aligned_band_rows(*writer, kBandRows);
    const auto next = [&](Band& band) {
      if (read_error || next_row >= layout.height) return false;
      band.y = next_row;
      band.rows = std::min(band_rows, layout.height - next_row);
      band.pixels.resize(row_samples * std::size_t(band.rows));
      band.view = band.pixels;
      next_row += band.rows;
      if (Status s = reader->read_rows(band.y, band.rows, band.pixels); !s) read_error = s.error();
      if (read_error || reader->failed()) stop = true;
      return true;
    };
    const auto prepare = [&](Band& band) {
      if (transform.apply) transform.apply(band.pixels, layout);
    };
    const Status written = write_bands(*writer, next, prepare, stop);
    if (read_error) return *read_error;
    if (!written) return written;
    if (Status s = reader->finish(); !s) return s;
    return writer->commit();
  });
}

}  // namespace matbake::image
