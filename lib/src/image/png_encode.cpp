#include "png_encode.hpp"

#include <libdeflate.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>

#include "huge_pages.hpp"

namespace matbake::image {
namespace {

enum Filter : std::uint8_t { kNone = 0, kSub = 1, kUp = 2, kAverage = 3, kPaeth = 4 };
constexpr int kFilterCount = 5;

std::uint8_t paeth_predictor(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return std::uint8_t(a);
  return std::uint8_t(pb <= pc ? b : c);
}

// Filters `row` (raw bytes, `previous` the raw row above, zeros for the first) with `filter` into
// `out`. The encoder reads only raw bytes, so every loop here is free of carried dependencies.
void apply_filter(Filter filter, const std::uint8_t* row, const std::uint8_t* previous, std::size_t n, std::size_t bpp,
                  std::uint8_t* out) {
  switch (filter) {
    case kNone: std::memcpy(out, row, n); return;
    case kSub:
      for (std::size_t i = 0; i < bpp; ++i) out[i] = row[i];
      for (std::size_t i = bpp; i < n; ++i) out[i] = std::uint8_t(row[i] - row[i - bpp]);
      return;
    case kUp:
      for (std::size_t i = 0; i < n; ++i) out[i] = std::uint8_t(row[i] - previous[i]);
      return;
    case kAverage:
      for (std::size_t i = 0; i < bpp; ++i) out[i] = std::uint8_t(row[i] - (previous[i] >> 1));
      for (std::size_t i = bpp; i < n; ++i) out[i] = std::uint8_t(row[i] - ((row[i - bpp] + previous[i]) >> 1));
      return;
    case kPaeth:
      for (std::size_t i = 0; i < bpp; ++i) out[i] = std::uint8_t(row[i] - previous[i]);  // a = c = 0: b
      for (std::size_t i = bpp; i < n; ++i) {
        out[i] = std::uint8_t(row[i] - paeth_predictor(row[i - bpp], previous[i], previous[i - bpp]));
      }
      return;
  }
}

// libpng's heuristic for choosing a row's filter: the smallest sum of the filtered bytes read as
// signed (small residuals compress well).
std::uint64_t signed_byte_sum(const std::uint8_t* bytes, std::size_t n) {
  std::uint64_t sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += bytes[i] < 128 ? bytes[i] : 256 - bytes[i];
  return sum;
}

void put_u32(std::string& out, std::uint32_t v) {
  const char bytes[4] = {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  out.append(bytes, 4);
}

void put_chunk(std::string& out, const char type[4], std::string_view data) {
  put_u32(out, std::uint32_t(data.size()));
  const std::size_t start = out.size();
  out.append(type, 4);
  out.append(data);
  put_u32(out, libdeflate_crc32(0, out.data() + start, out.size() - start));
}

std::string u32_bytes(std::initializer_list<std::uint32_t> values) {
  std::string s;
  for (std::uint32_t v : values) put_u32(s, v);
  return s;
}

// The colour chunks OIIO's PNG writer puts for the same tag, so readers (and OIIO reading back)
// see the same encoding: sRGB with its gAMA and cHRM fallbacks, gAMA alone for a power law.
void put_colour_chunks(std::string& out, std::string_view colorspace) {
  if (colorspace == "sRGB") {
    put_chunk(out, "gAMA", u32_bytes({45455}));
    put_chunk(out, "sRGB", std::string_view("\x03", 1));  // rendering intent: absolute colorimetric
    put_chunk(out, "cHRM", u32_bytes({31270, 32900, 64000, 33000, 30000, 60000, 15000, 6000}));
  } else if (colorspace == "Linear") {
    put_chunk(out, "gAMA", u32_bytes({100000}));
  } else if (colorspace == "Gamma2.2") {
    put_chunk(out, "gAMA", u32_bytes({45455}));
  }
  if (!colorspace.empty()) put_chunk(out, "tEXt", "oiio:ColorSpace" + std::string(1, '\0') + std::string(colorspace));
}

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

}  // namespace

PngEncoder::PngEncoder(const ImageLayout& layout, int bits, int level, std::string_view colorspace)
    : width_(layout.width), height_(layout.height), channels_(layout.channels), bits_(bits), level_(level),
      colorspace_(colorspace), row_bytes_(std::size_t(layout.width) * std::size_t(layout.channels) * std::size_t(bits / 8)),
      pixel_bytes_(std::size_t(layout.channels) * std::size_t(bits / 8)) {
  reserve_advised(filtered_, (row_bytes_ + 1) * std::size_t(height_));
  previous_.assign(row_bytes_, 0);
  current_.resize(row_bytes_);
  candidate_.resize(row_bytes_ * kFilterCount);
}

void PngEncoder::filter_row(const std::uint8_t* row) {
  std::uint64_t best_sum = UINT64_MAX;
  int best = kNone;
  // Stored (level 0): a filter cannot make stored bytes smaller, so none is tried.
  const int tried = level_ == 0 ? kNone + 1 : kFilterCount;
  for (int f = kNone; f < tried; ++f) {
    std::uint8_t* out = candidate_.data() + std::size_t(f) * row_bytes_;
    apply_filter(Filter(f), row, previous_.data(), row_bytes_, pixel_bytes_, out);
    const std::uint64_t sum = signed_byte_sum(out, row_bytes_);
    if (sum < best_sum) best_sum = sum, best = f;
  }
  filtered_.push_back(std::uint8_t(best));
  const std::uint8_t* chosen = candidate_.data() + std::size_t(best) * row_bytes_;
  filtered_.insert(filtered_.end(), chosen, chosen + row_bytes_);
  std::memcpy(previous_.data(), row, row_bytes_);
}

void PngEncoder::add_rows(std::span<const std::uint8_t> samples) {
  for (std::size_t offset = 0; offset + row_bytes_ <= samples.size(); offset += row_bytes_) filter_row(samples.data() + offset);
}

void PngEncoder::add_rows(std::span<const std::uint16_t> samples) {
  const std::size_t row_samples = row_bytes_ / 2;
  for (std::size_t offset = 0; offset + row_samples <= samples.size(); offset += row_samples) {
    for (std::size_t i = 0; i < row_samples; ++i) {  // PNG stores 16-bit samples big-endian
      current_[2 * i] = std::uint8_t(samples[offset + i] >> 8);
      current_[2 * i + 1] = std::uint8_t(samples[offset + i]);
    }
    filter_row(current_.data());
  }
}

std::string PngEncoder::finish() {
  std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor(libdeflate_alloc_compressor(level_));
  if (!compressor) throw std::bad_alloc();
  // Not zero-filled: libdeflate writes it, and only what it writes is read.
  const std::size_t bound = libdeflate_zlib_compress_bound(compressor.get(), filtered_.size());
  const std::unique_ptr<char[]> zlib_bytes(new char[bound]);
  advise_huge_pages(zlib_bytes.get(), bound);
  const std::string_view zlib(zlib_bytes.get(), libdeflate_zlib_compress(compressor.get(), filtered_.data(),
                                                                         filtered_.size(), zlib_bytes.get(), bound));
  std::vector<std::uint8_t>().swap(filtered_);

  constexpr int kColourType[5] = {0, 0, 4, 2, 6};  // by channel count: gray, gray+alpha, RGB, RGBA
  std::string header = u32_bytes({std::uint32_t(width_), std::uint32_t(height_)});
  header += {char(bits_), char(kColourType[channels_]), 0, 0, 0};  // deflate, adaptive filters, no interlace

  // IDAT chunks of 1 MiB: readers that stream need not hold the whole stream in one chunk.
  constexpr std::size_t kIdatBytes = std::size_t{1} << 20;
  std::string png;
  png.reserve(zlib.size() + zlib.size() / kIdatBytes * 12 + 256);
  advise_huge_pages(png.data(), png.capacity());
  png.append("\x89PNG\r\n\x1a\n", 8);
  put_chunk(png, "IHDR", header);
  put_colour_chunks(png, colorspace_);
  for (std::size_t at = 0; at < zlib.size(); at += kIdatBytes) {
    put_chunk(png, "IDAT", zlib.substr(at, kIdatBytes));
  }
  put_chunk(png, "IEND", {});
  return png;
}

}  // namespace matbake::image
