#include "exr_encode.hpp"

#include <OpenEXR/openexr.h>
#include <fcntl.h>
#include <libdeflate.h>
#include <unistd.h>

#include <Imath/half.h>
#include <algorithm>
#include <charconv>
#include <cstring>
#include <memory>
#include <new>

namespace fs = std::filesystem;

namespace matbake::image {
namespace {

// libdeflate's level for plain "zip"/"zips": the size of OpenEXR 3.1's own zlib output or smaller
// (measured in docs/performance.md).
constexpr int kDefaultZipLevel = 6;

}  // namespace

// Where the core's writes go: a file (positioned writes: the offset table is written last, at its
// place after the header) or a growing buffer.
struct ExrStream {
  int fd = -1;
  std::vector<unsigned char>* memory = nullptr;
  std::string first_error;
};

namespace {

int64_t write_at(exr_const_context_t, void* user, const void* buffer, uint64_t size, uint64_t offset,
                 exr_stream_error_func_ptr_t) {
  auto* stream = static_cast<ExrStream*>(user);  // NOLINT: the core's opaque user data
  if (stream->memory != nullptr) {
    if (stream->memory->size() < offset + size) stream->memory->resize(offset + size);
    std::memcpy(stream->memory->data() + offset, buffer, size);
    return int64_t(size);
  }
  const auto* bytes = static_cast<const unsigned char*>(buffer);
  uint64_t done = 0;
  while (done < size) {
    const ssize_t n = ::pwrite(stream->fd, bytes + done, size - done, off_t(offset + done));
    if (n <= 0) {
      if (n < 0 && errno == EINTR) continue;
      if (stream->first_error.empty()) stream->first_error = std::string("cannot write: ") + std::strerror(errno);
      return -1;
    }
    done += uint64_t(n);
  }
  return int64_t(size);
}

// The core calls its error handler with the context locked, so the handler cannot ask the context
// for its user data (exr_get_user_data would wait on that lock for ever): the stream whose call is
// under way, in this thread, is named here instead.
thread_local ExrStream* t_reporting_stream = nullptr;

struct ReportingTo {
  explicit ReportingTo(ExrStream* stream) { t_reporting_stream = stream; }
  ~ReportingTo() { t_reporting_stream = nullptr; }
  ReportingTo(const ReportingTo&) = delete;
  ReportingTo& operator=(const ReportingTo&) = delete;
};

void keep_first_error(exr_const_context_t, exr_result_t, const char* message) {
  ExrStream* stream = t_reporting_stream;
  if (stream != nullptr && stream->first_error.empty()) stream->first_error = message;
}

// A libdeflate compressor per thread and level, kept: making one allocates several hundred KB.
libdeflate_compressor* compressor_for(int level) {
  struct Free {
    void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
  };
  thread_local std::unique_ptr<libdeflate_compressor, Free> compressor;
  thread_local int compressor_level = -1;
  if (compressor_level != level) {
    compressor.reset(libdeflate_alloc_compressor(level));
    if (!compressor) throw std::bad_alloc();
    compressor_level = level;
  }
  return compressor.get();
}

// EXR's ZIP stores a chunk's bytes split into its even and odd bytes (the low and high bytes of
// each 16-bit word apart), each then as its difference to the one before plus 128, deflated in a
// zlib stream. `split` holds the split bytes; the differences are taken in place. Returns the
// stored size in `out` (room for split.size() - 1), or 0 when the chunk does not get smaller:
// it is then stored raw, which readers know from its size.
std::size_t zip_split_bytes(std::vector<std::uint8_t>& split, std::uint8_t* out, int level) {
  const std::size_t n = split.size();
  if (n < 2) return 0;
  for (std::size_t i = n - 1; i > 0; --i) split[i] = std::uint8_t(split[i] - split[i - 1] + 128);
  return libdeflate_zlib_compress(compressor_for(level), split.data(), n, out, n - 1);
}

std::optional<int> level_suffix(std::string_view rest) {
  if (rest.empty()) return kDefaultZipLevel;
  if (rest.front() != ':') return std::nullopt;
  int level = 0;
  const char* first = rest.data() + 1;
  const char* last = rest.data() + rest.size();
  const auto [end, ec] = std::from_chars(first, last, level);
  if (ec != std::errc() || end != last || level < 1 || level > 9) return std::nullopt;
  return level;
}

}  // namespace

std::optional<ExrCompression> exr_compression_from_name(std::string_view name) {
  if (name == "none") return ExrCompression{ExrCodec::none, 0};
  for (const auto& [prefix, codec] : {std::pair{std::string_view("zips"), ExrCodec::zips},
                                      std::pair{std::string_view("zip"), ExrCodec::zip}}) {
    if (name.substr(0, prefix.size()) != prefix) continue;
    const std::optional<int> level = level_suffix(name.substr(prefix.size()));
    if (!level) return std::nullopt;
    return ExrCompression{codec, *level};
  }
  return std::nullopt;
}

Error ExrEncoder::failure(int result) const {
  const std::string& message = stream_->first_error;
  return Error{name_, "cannot write OpenEXR: " + (message.empty() ? std::string(exr_get_default_error_message(result))
                                                                  : message)};
}

Result<ExrEncoder> ExrEncoder::open(const fs::path& file, const std::string& name, std::vector<unsigned char>* memory,
                                    const ImageLayout& layout, SampleType type, ExrCompression compression,
                                    std::string_view colorspace) {
  ExrEncoder encoder;
  encoder.name_ = name;
  encoder.width_ = layout.width;
  encoder.channels_ = layout.channels;
  encoder.half_ = type == SampleType::half;
  encoder.compress_ = compression.codec != ExrCodec::none;
  encoder.chunk_rows_ = compression.codec == ExrCodec::zip ? 16 : 1;
  encoder.level_ = compression.level;
  encoder.stream_ = new ExrStream;
  encoder.stream_->memory = memory;
  if (memory == nullptr) {
    encoder.stream_->fd = ::open(file.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (encoder.stream_->fd < 0) return Error{name, std::string("cannot write: ") + std::strerror(errno)};
  }

  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.user_data = encoder.stream_;
  init.write_fn = write_at;
  init.error_handler_fn = keep_first_error;
  exr_context_t context = nullptr;
  const ReportingTo reporting(encoder.stream_);
  exr_result_t result = exr_start_write(&context, name.c_str(), EXR_WRITE_FILE_DIRECTLY, &init);
  encoder.context_ = context;
  if (result != EXR_ERR_SUCCESS) return encoder.failure(result);

  const exr_compression_t codec = compression.codec == ExrCodec::zip    ? EXR_COMPRESSION_ZIP
                                  : compression.codec == ExrCodec::zips ? EXR_COMPRESSION_ZIPS
                                                                        : EXR_COMPRESSION_NONE;
  int part = 0;
  result = exr_add_part(context, "", EXR_STORAGE_SCANLINE, &part);
  if (result == EXR_ERR_SUCCESS) {
    result = exr_initialize_required_attr_simple(context, part, layout.width, layout.height, codec);
  }
  const std::vector<std::string>& names = layout.channel_names;
  if (names.size() != std::size_t(layout.channels)) return Error{name, "internal: channels without names"};
  for (const std::string& channel : names) {
    if (result != EXR_ERR_SUCCESS) break;
    result = exr_add_channel(context, part, channel.c_str(), encoder.half_ ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
  }
  if (result == EXR_ERR_SUCCESS && !colorspace.empty()) {
    result = exr_attr_set_string(context, part, "oiio:ColorSpace", std::string(colorspace).c_str());
  }
  if (result == EXR_ERR_SUCCESS) result = exr_write_header(context);
  if (result != EXR_ERR_SUCCESS) return encoder.failure(result);

  // The core keeps the channel list sorted by name, as the format requires.
  const exr_attr_chlist_t* list = nullptr;
  if (exr_get_channels(context, part, &list) != EXR_ERR_SUCCESS || list->num_channels != layout.channels) {
    return Error{name, "cannot write OpenEXR: channel names are not distinct"};
  }
  for (int c = 0; c < list->num_channels; ++c) {
    const std::string_view stored(list->entries[c].name.str, std::size_t(list->entries[c].name.length));
    encoder.file_order_.push_back(int(std::find(names.begin(), names.end(), stored) - names.begin()));
  }
  return encoder;
}

ExrEncoder::ExrEncoder(ExrEncoder&& other) noexcept
    : name_(std::move(other.name_)), context_(other.context_), stream_(other.stream_), width_(other.width_),
      channels_(other.channels_), chunk_rows_(other.chunk_rows_), level_(other.level_), half_(other.half_),
      compress_(other.compress_), file_order_(std::move(other.file_order_)) {
  other.context_ = nullptr;
  other.stream_ = nullptr;
}

ExrEncoder::~ExrEncoder() {
  if (context_ != nullptr) {
    auto context = static_cast<exr_context_t>(context_);
    const ReportingTo reporting(stream_);
    exr_finish(&context);
  }
  if (stream_ != nullptr) {
    if (stream_->fd >= 0) ::close(stream_->fd);
    delete stream_;
  }
}

// Calls put(w, word) for the 16-bit words of rows [first, first + count) as a chunk stores them:
// row by row, one channel after the other (file order), a half sample one word, a float its low
// word then its high word.
template <class Put>
void for_each_word(const float* samples, std::size_t width, std::size_t channels, const std::vector<int>& file_order,
                   bool to_half, int first, int count, Put put) {
  std::size_t w = 0;
  for (int row = first; row < first + count; ++row) {
    const float* pixels = samples + std::size_t(row) * width * channels;
    for (const int c : file_order) {
      const float* channel = pixels + std::size_t(c);
      if (to_half) {
        for (std::size_t x = 0; x < width; ++x) put(w++, half(channel[x * channels]).bits());  // nearest, ties to even
      } else {
        for (std::size_t x = 0; x < width; ++x) {
          std::uint32_t bits = 0;
          std::memcpy(&bits, &channel[x * channels], 4);
          put(w++, std::uint16_t(bits));
          put(w++, std::uint16_t(bits >> 16));
        }
      }
    }
  }
}

void ExrEncoder::encode(int y, int rows, std::span<const float> samples, std::vector<ExrChunk>& chunks) const {
  const std::size_t width = std::size_t(width_), channels = std::size_t(channels_);
  const std::size_t sample_bytes = half_ ? 2 : 4;
  thread_local std::vector<std::uint8_t> split;  // reused: fresh pages cost more than the deflate
  chunks.resize(std::size_t((rows + chunk_rows_ - 1) / chunk_rows_));
  for (int first = 0; first < rows; first += chunk_rows_) {
    const int count = std::min(chunk_rows_, rows - first);
    ExrChunk& chunk = chunks[std::size_t(first / chunk_rows_)];
    chunk.y = y + first;
    const std::size_t n = std::size_t(count) * width * channels * sample_bytes;
    chunk.bytes.resize(n);
    const auto pack_raw = [&] {
      std::uint8_t* out = chunk.bytes.data();
      for_each_word(samples.data(), width, channels, file_order_, half_, first, count, [out](std::size_t w, std::uint16_t v) {
        out[2 * w] = std::uint8_t(v);  // little-endian
        out[2 * w + 1] = std::uint8_t(v >> 8);
      });
    };
    if (!compress_) {
      pack_raw();
      continue;
    }
    // Packed straight into ZIP's split order: low bytes in the first half, high bytes in the second.
    split.resize(n);
    std::uint8_t* low = split.data();
    std::uint8_t* high = split.data() + n / 2;
    for_each_word(samples.data(), width, channels, file_order_, half_, first, count, [low, high](std::size_t w, std::uint16_t v) {
      low[w] = std::uint8_t(v);
      high[w] = std::uint8_t(v >> 8);
    });
    const std::size_t stored = zip_split_bytes(split, chunk.bytes.data(), level_);
    if (stored > 0) {
      chunk.bytes.resize(stored);
    } else {
      pack_raw();
    }
  }
}

Status ExrEncoder::write(const std::vector<ExrChunk>& chunks) {
  auto context = static_cast<exr_context_t>(context_);
  const ReportingTo reporting(stream_);
  for (const ExrChunk& chunk : chunks) {
    const exr_result_t result = exr_write_scanline_chunk(context, 0, chunk.y, chunk.bytes.data(), chunk.bytes.size());
    if (result != EXR_ERR_SUCCESS) return failure(result);
  }
  return success();
}

Status ExrEncoder::finish() {
  auto context = static_cast<exr_context_t>(context_);
  const ReportingTo reporting(stream_);
  context_ = nullptr;
  const exr_result_t result = exr_finish(&context);
  if (result != EXR_ERR_SUCCESS || !stream_->first_error.empty()) return failure(result);
  if (stream_->fd >= 0) {
    const int fd = stream_->fd;
    stream_->fd = -1;
    if (::close(fd) != 0) return Error{name_, std::string("cannot write: ") + std::strerror(errno)};
  }
  return success();
}

}  // namespace matbake::image
