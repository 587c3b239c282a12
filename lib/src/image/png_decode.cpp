#include "png_decode.hpp"

#include <spng.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <vector>

namespace matbake::image {
namespace {

constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

// Ancillary chunks (text, ICC profiles, ...) are cached by libspng up to these sizes; a file that
// declares more is refused rather than allocated for.
constexpr std::size_t kChunkLimit = std::size_t{64} << 20;
constexpr std::size_t kChunkCacheLimit = std::size_t{256} << 20;

enum ColourType { kGray = 0, kRgb = 2, kPalette = 3, kGrayAlpha = 4, kRgbAlpha = 6 };

struct ContextDeleter {
  void operator()(spng_ctx* c) const { spng_ctx_free(c); }
};
struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

class PngDecoder final : public StoredReader {
 public:
  static Result<std::unique_ptr<StoredReader>> open(const std::string& name, std::span<const unsigned char> memory) {
    auto decoder = std::unique_ptr<PngDecoder>(new PngDecoder(name));
    if (Status s = decoder->start(memory); !s) return s.error();
    return std::unique_ptr<StoredReader>(std::move(decoder));
  }

  Status read(int y, int rows, void* samples) override {
    if (y != next_row_) return Error{name_, "internal: PNG rows asked for out of order"};
    const std::size_t row_bytes = row_bytes_;
    auto* out = static_cast<unsigned char*>(samples);
    if (interlaced_) {
      if (whole_.empty()) {
        whole_.resize(row_bytes * std::size_t(format_.layout.height));
        if (int e = spng_decode_image(context_.get(), whole_.data(), whole_.size(), decode_format_, decode_flags_)) {
          return pixel_problem(e);
        }
      }
      std::memcpy(out, whole_.data() + std::size_t(y) * row_bytes, std::size_t(rows) * row_bytes);
    } else {
      for (int r = 0; r < rows; ++r) {
        const int e = spng_decode_row(context_.get(), out + std::size_t(r) * row_bytes, row_bytes);
        // SPNG_EOI comes with the last row; the image's end is checked there.
        if (e != 0 && !(e == SPNG_EOI && y + r + 1 == format_.layout.height)) return pixel_problem(e);
      }
    }
    next_row_ = y + rows;
    // The chunks after the pixels, to IEND: a file cut after its last row (in the IDAT's CRC, or
    // before IEND) is truncated, as libpng finds, though the pixels are all there.
    if (next_row_ == format_.layout.height) {
      if (int e = spng_decode_chunks(context_.get())) return pixel_problem(e);
    }
    return success();
  }

 private:
  explicit PngDecoder(std::string name) : name_(std::move(name)) {}

  // In the header, or (as OIIO's readers say) in the pixels.
  Error problem(int e) const { return Error{name_, std::string("not a readable image: PNG: ") + spng_strerror(e)}; }
  Error pixel_problem(int e) const { return Error{name_, std::string("cannot read pixels: PNG: ") + spng_strerror(e)}; }

  Status start(std::span<const unsigned char> memory) {
    context_.reset(spng_ctx_new(0));
    if (!context_) throw std::bad_alloc();
    spng_ctx* c = context_.get();
    // As libpng: a damaged critical chunk is an error, a damaged ancillary one is dropped.
    spng_set_crc_action(c, SPNG_CRC_ERROR, SPNG_CRC_DISCARD);
    spng_set_chunk_limits(c, kChunkLimit, kChunkCacheLimit);
    spng_set_option(c, SPNG_KEEP_UNKNOWN_CHUNKS, 1);  // cICP is one to libspng 0.7
    if (!memory.empty()) {
      if (int e = spng_set_png_buffer(c, memory.data(), memory.size())) return problem(e);
    } else {
      file_.reset(std::fopen(name_.c_str(), "rb"));
      if (!file_) return Error{name_, std::string("cannot open: ") + std::strerror(errno)};
      if (int e = spng_set_png_file(c, file_.get())) return problem(e);
    }
    spng_ihdr header{};
    if (int e = spng_get_ihdr(c, &header)) return problem(e);
    if (Status s = check_image_size(name_, header.width, header.height); !s) return s;
    spng_trns transparency{};
    const bool has_trns = spng_get_trns(c, &transparency) == 0;
    const bool deep = header.bit_depth == 16;
    ImageLayout& layout = format_.layout;
    layout.width = int(header.width);
    layout.height = int(header.height);
    switch (header.color_type) {
      case kGray:
        layout.channels = has_trns ? 2 : 1;
        decode_format_ = has_trns ? (deep ? SPNG_FMT_GA16 : SPNG_FMT_GA8) : (deep ? SPNG_FMT_PNG : SPNG_FMT_G8);
        break;
      case kGrayAlpha:
        layout.channels = 2;
        decode_format_ = SPNG_FMT_PNG;
        break;
      case kRgb:
        layout.channels = has_trns ? 4 : 3;
        decode_format_ = has_trns ? (deep ? SPNG_FMT_RGBA16 : SPNG_FMT_RGBA8) : (deep ? SPNG_FMT_PNG : SPNG_FMT_RGB8);
        break;
      case kPalette:
        layout.channels = has_trns ? 4 : 3;
        decode_format_ = has_trns ? SPNG_FMT_RGBA8 : SPNG_FMT_RGB8;
        break;
      case kRgbAlpha:
        layout.channels = 4;
        decode_format_ = SPNG_FMT_PNG;
        break;
      default: return Error{name_, "not a readable image: PNG: colour type " + std::to_string(header.color_type)};
    }
    decode_flags_ = has_trns ? SPNG_DECODE_TRNS : 0;
    layout.channel_names = layout.channels == 2 ? std::vector<std::string>{"Y", "A"} : default_channel_names(layout.channels);
    layout.alpha_channel = layout.channels == 2 || layout.channels == 4 ? layout.channels - 1 : -1;
    format_.stored = deep && header.color_type != kPalette ? SampleType::u16 : SampleType::u8;
    format_.format_name = "png";
    read_colour_tag();
    row_bytes_ = std::size_t(layout.width) * std::size_t(layout.channels) * (format_.stored == SampleType::u16 ? 2 : 1);
    interlaced_ = header.interlace_method != 0;
    if (!interlaced_) {
      // This reads on to the first IDAT: a failure is in or next to the pixels, as OIIO reported it.
      if (int e = spng_decode_image(c, nullptr, 0, decode_format_, decode_flags_ | SPNG_DECODE_PROGRESSIVE)) {
        return pixel_problem(e);
      }
    }
    return success();
  }

  // The PNG's own colour declaration, in the order PNG's third edition ranks them: cICP, iCCP,
  // sRGB, gAMA. These chunks come before the pixels, so they are read by now.
  void read_colour_tag() {
    spng_ctx* c = context_.get();
    std::uint32_t count = 0;
    if (spng_get_unknown_chunks(c, nullptr, &count) == 0 && count > 0) {
      std::vector<spng_unknown_chunk> chunks(count);
      if (spng_get_unknown_chunks(c, chunks.data(), &count) == 0) {
        for (const spng_unknown_chunk& chunk : chunks) {
          if (std::memcmp(chunk.type, "cICP", 4) != 0 || chunk.length < 4) continue;
          const int transfer = static_cast<const unsigned char*>(chunk.data)[1];
          if (transfer == 13) format_.tagged = color::Transfer::srgb;
          else if (transfer == 8) format_.tagged = color::Transfer::linear;
          else if (transfer == 4) format_.tagged = color::Transfer::gamma22;
          format_.tag = "cICP transfer " + std::to_string(transfer);
          return;  // a cICP matbake cannot interpret still outranks the rest
        }
      }
    }
    spng_iccp profile{};
    if (spng_get_iccp(c, &profile) == 0) {
      std::string name(profile.profile_name, strnlen(profile.profile_name, sizeof profile.profile_name));
      format_.tag = "iCCP profile '" + name + "'";
      std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
      if (name.find("srgb") != std::string::npos) format_.tagged = color::Transfer::srgb;
      return;
    }
    std::uint8_t intent = 0;
    if (spng_get_srgb(c, &intent) == 0) {
      format_.tagged = color::Transfer::srgb;
      format_.tag = "sRGB chunk";
      return;
    }
    std::uint32_t gamma = 0;  // the file's gamma × 100000: 45455 is 1/2.2, 100000 is 1 (linear)
    if (spng_get_gama_int(c, &gamma) == 0) {
      if (gamma >= 45400 && gamma <= 45500) format_.tagged = color::Transfer::gamma22;
      else if (gamma >= 99900 && gamma <= 100100) format_.tagged = color::Transfer::linear;
      format_.tag = "gAMA " + std::to_string(gamma / 100000.0);
    }
  }

  std::string name_;
  std::unique_ptr<std::FILE, FileCloser> file_;       // declared before context_: outlives it
  std::unique_ptr<spng_ctx, ContextDeleter> context_;
  int decode_format_ = SPNG_FMT_PNG;
  int decode_flags_ = 0;
  std::size_t row_bytes_ = 0;
  bool interlaced_ = false;
  int next_row_ = 0;
  std::vector<unsigned char> whole_;  // an interlaced image, decoded on the first band
};

}  // namespace

bool has_png_signature(std::span<const unsigned char> bytes) {
  return bytes.size() >= sizeof kSignature && std::memcmp(bytes.data(), kSignature, sizeof kSignature) == 0;
}

Result<std::unique_ptr<StoredReader>> open_png(const std::string& name, std::span<const unsigned char> memory) {
  return PngDecoder::open(name, memory);
}

}  // namespace matbake::image
