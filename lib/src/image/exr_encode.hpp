#pragma once
// Scanline OpenEXR with half or float samples, uncompressed, ZIP (16 rows a chunk) or ZIPS (one
// row), written by matbake instead of OIIO: OpenEXR's C core lays out the header, the offset table
// and the chunks, and each chunk is deflated with libdeflate (2–3× zlib's speed at equal size;
// docs/performance.md). Every other EXR compression goes through OIIO as before.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/image.hpp"
#include "matbake/result.hpp"

namespace matbake::image {

enum class ExrCodec { none, zips, zip };

struct ExrCompression {
  ExrCodec codec = ExrCodec::zip;
  int level = 0;  // libdeflate's level (1 to 12; for zip/zips); the name's ":N" when given
};

// The compressions this encoder writes, from OIIO's names: "none", "zip", "zips", "zip:N",
// "zips:N" (N: 1 to 9, zlib's scale, which libdeflate's levels follow). Anything else: nullopt,
// and OIIO writes the file.
std::optional<ExrCompression> exr_compression_from_name(std::string_view name);

// One chunk as stored: its first row and its bytes (compressed, or raw when that is not smaller).
struct ExrChunk {
  int y = 0;
  std::vector<std::uint8_t> bytes;
};

struct ExrStream;  // where the core's writes go (exr_encode.cpp)

class ExrEncoder {
 public:
  // Writes to `file` (created empty beforehand) or, when `memory` is given, into it; errors name
  // `name`. The layout's channels are named. `type` half or f32. `colorspace` is written as the string attribute oiio:ColorSpace
  // when not empty, as OIIO does.
  static Result<ExrEncoder> open(const std::filesystem::path& file, const std::string& name,
                                 std::vector<unsigned char>* memory,
                                 const ImageLayout& layout, SampleType type, ExrCompression compression,
                                 std::string_view colorspace);
  ExrEncoder(ExrEncoder&& other) noexcept;
  ExrEncoder& operator=(ExrEncoder&&) = delete;
  ~ExrEncoder();

  // Rows in a chunk: bands given to encode() start at a multiple of it.
  int chunk_rows() const { return chunk_rows_; }

  // Rows [y, y + rows) of interleaved samples (already encoded) into `chunks`, whose storage is
  // reused. Thread-safe: bands are encoded in parallel and written in order.
  void encode(int y, int rows, std::span<const float> samples, std::vector<ExrChunk>& chunks) const;

  Status write(const std::vector<ExrChunk>& chunks);
  // The offset table; the file is complete after it.
  Status finish();

 private:
  ExrEncoder() = default;
  Error failure(int result) const;  // an exr_result_t, or the first message the core gave

  std::string name_;  // for errors
  void* context_ = nullptr;  // exr_context_t
  ExrStream* stream_ = nullptr;
  int width_ = 0, channels_ = 0, chunk_rows_ = 1, level_ = 0;
  bool half_ = true, compress_ = true;
  std::vector<int> file_order_;  // the file's channels (sorted by name): index into the interleaved samples
};

}  // namespace matbake::image
