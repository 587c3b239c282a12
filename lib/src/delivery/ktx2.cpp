// KTX2 files, little-endian: the 80-byte header and index, the level index, the DFD, the key/value
// data, the supercompression global data, then the levels, smallest first.
#include "matbake/ktx2.hpp"

#include "matbake/image.hpp"

#include <zstd.h>

#include <algorithm>
#include <cstring>

namespace matbake::ktx2 {
namespace {

constexpr unsigned char kIdentifier[12] = {0xAB, 'K', 'T', 'X', ' ', '2', '0', 0xBB, '\r', '\n', 0x1A, '\n'};
constexpr std::size_t kLevelIndexEntryBytes = 24;
constexpr std::size_t kUastcBlockBytes = 16;
constexpr std::size_t kMaxLevels = 15;  // 16384 × 16384 down to 1 × 1

std::uint32_t u32_at(std::span<const unsigned char> b, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}
std::uint64_t u64_at(std::span<const unsigned char> b, std::size_t at) {
  std::uint64_t v;
  std::memcpy(&v, b.data() + at, 8);
  return v;
}
void put_u32(std::vector<unsigned char>& out, std::size_t at, std::uint32_t v) { std::memcpy(out.data() + at, &v, 4); }
void put_u64(std::vector<unsigned char>& out, std::size_t at, std::uint64_t v) { std::memcpy(out.data() + at, &v, 8); }
void append_u32(std::vector<unsigned char>& out, std::uint32_t v) {
  out.resize(out.size() + 4);
  put_u32(out, out.size() - 4, v);
}
std::size_t aligned(std::size_t at, std::size_t alignment) { return (at + alignment - 1) / alignment * alignment; }

// [offset, offset + length) lies within a file of `size` bytes.
bool within(std::uint64_t offset, std::uint64_t length, std::size_t size) { return offset <= size && length <= size - offset; }

Descriptor descriptor_of(const std::vector<std::uint32_t>& dfd) {
  Descriptor d;
  if (dfd.size() < 7) return d;  // total size + the 24-byte block header
  d.model = std::uint8_t(dfd[3]), d.primaries = std::uint8_t(dfd[3] >> 8), d.transfer = std::uint8_t(dfd[3] >> 16);
  d.flags = std::uint8_t(dfd[3] >> 24);
  d.block_width = std::uint8_t((dfd[4] & 0xFF) + 1), d.block_height = std::uint8_t(((dfd[4] >> 8) & 0xFF) + 1);
  d.bytes_plane0 = std::uint8_t(dfd[5]);
  const std::size_t block_bytes = dfd[2] >> 16;
  for (std::size_t s = 0; 24 + 16 * (s + 1) <= block_bytes && 7 + 4 * s < dfd.size(); ++s) {
    d.channels.push_back(std::uint8_t((dfd[7 + 4 * s] >> 24) & 0x0F));
  }
  return d;
}

Result<std::vector<std::pair<std::string, std::string>>> key_values_of(std::span<const unsigned char> kvd, const std::string& name) {
  std::vector<std::pair<std::string, std::string>> out;
  for (std::size_t at = 0; at + 4 <= kvd.size();) {
    const std::uint32_t length = u32_at(kvd, at);
    if (!within(at + 4, length, kvd.size())) return Error{name, "KTX2 key/value data runs past its end"};
    const std::string entry(reinterpret_cast<const char*>(kvd.data() + at + 4), length);
    const std::size_t nul = entry.find('\0');
    if (nul == std::string::npos) return Error{name, "KTX2 key without its terminating NUL"};
    std::string value = entry.substr(nul + 1);
    if (!value.empty() && value.back() == '\0') value.pop_back();
    out.emplace_back(entry.substr(0, nul), std::move(value));
    at = aligned(at + 4 + length, 4);
  }
  return out;
}

}  // namespace

namespace {

// A KTX2 file from `bytes`, its first bytes (all of it when `with_levels`), of `file_size` bytes.
Result<Texture> read_file(std::span<const unsigned char> bytes, std::uint64_t file_size, bool with_levels, const std::string& name) {
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kIdentifier, sizeof kIdentifier) != 0) {
    return Error{name, "not a KTX2 file (no KTX 20 identifier)"};
  }
  Texture t;
  t.vk_format = u32_at(bytes, 12), t.type_size = u32_at(bytes, 16);
  t.width = u32_at(bytes, 20), t.height = u32_at(bytes, 24);
  const std::uint32_t depth = u32_at(bytes, 28), layers = u32_at(bytes, 32), faces = u32_at(bytes, 36);
  const std::uint32_t level_count = std::max<std::uint32_t>(1, u32_at(bytes, 40));
  t.supercompression = u32_at(bytes, 44);
  if (depth != 0 || layers != 0 || faces != 1) return Error{name, "KTX2 file is not a plain 2D texture (depth, layers or faces)"};
  // Within the pixel limit of every image matbake holds, before any level is inflated.
  if (Status s = image::check_image_size(name, t.width, t.height); !s) return s.error();
  if (level_count > kMaxLevels) return Error{name, "KTX2 file declares " + std::to_string(level_count) + " levels"};
  const std::uint32_t dfd_offset = u32_at(bytes, 48), dfd_length = u32_at(bytes, 52);
  const std::uint32_t kvd_offset = u32_at(bytes, 56), kvd_length = u32_at(bytes, 60);
  const std::uint64_t sgd_offset = u64_at(bytes, 64), sgd_length = u64_at(bytes, 72);
  if (!within(kHeaderBytes, level_count * kLevelIndexEntryBytes, bytes.size()) || !within(dfd_offset, dfd_length, bytes.size()) ||
      !within(kvd_offset, kvd_length, bytes.size()) || !within(sgd_offset, sgd_length, bytes.size())) {
    return Error{name, "KTX2 index points past the end of the file"};
  }
  if (dfd_length < 28 || dfd_length % 4 != 0 || u32_at(bytes, dfd_offset) != dfd_length) {
    return Error{name, "KTX2 data format descriptor is malformed"};
  }
  for (std::size_t w = 0; w < dfd_length / 4; ++w) t.dfd.push_back(u32_at(bytes, dfd_offset + 4 * w));
  t.descriptor = descriptor_of(t.dfd);
  auto kv = key_values_of(bytes.subspan(kvd_offset, kvd_length), name);
  if (!kv) return kv.error();
  t.key_values = std::move(*kv);
  t.global_data.assign(bytes.begin() + std::ptrdiff_t(sgd_offset), bytes.begin() + std::ptrdiff_t(sgd_offset + sgd_length));
  for (std::size_t l = 0; l < level_count; ++l) {
    const std::size_t entry = kHeaderBytes + l * kLevelIndexEntryBytes;
    const std::uint64_t offset = u64_at(bytes, entry), length = u64_at(bytes, entry + 8);
    if (!within(offset, length, file_size)) return Error{name, "KTX2 level " + std::to_string(l) + " lies past the end of the file"};
    Level level;
    if (with_levels) level.bytes.assign(bytes.begin() + std::ptrdiff_t(offset), bytes.begin() + std::ptrdiff_t(offset + length));
    level.byte_length = length;
    level.uncompressed_length = u64_at(bytes, entry + 16);
    t.levels.push_back(std::move(level));
  }
  return t;
}

}  // namespace

Result<Texture> read(std::span<const unsigned char> bytes, const std::string& name) { return read_file(bytes, bytes.size(), true, name); }

std::uint64_t header_extent(std::span<const unsigned char> first) {
  if (first.size() < kHeaderBytes || std::memcmp(first.data(), kIdentifier, sizeof kIdentifier) != 0) return 0;
  const std::uint64_t levels = std::max<std::uint32_t>(1, u32_at(first, 40));
  return std::max({kHeaderBytes + std::min<std::uint64_t>(levels, kMaxLevels + 1) * kLevelIndexEntryBytes,
                   std::uint64_t(u32_at(first, 48)) + u32_at(first, 52), std::uint64_t(u32_at(first, 56)) + u32_at(first, 60),
                   u64_at(first, 64) + std::min<std::uint64_t>(u64_at(first, 72), UINT64_MAX - u64_at(first, 64))});
}

Result<Texture> read_header(std::span<const unsigned char> head, std::uint64_t file_size, const std::string& name) {
  return read_file(head, file_size, false, name);
}

Result<std::vector<unsigned char>> level_data(const Texture& texture, std::size_t level, const std::string& name) {
  if (level >= texture.levels.size()) return Error{name, "KTX2 file has no level " + std::to_string(level)};
  const Level& l = texture.levels[level];
  if (texture.supercompression != kSupercompressionZstd) return l.bytes;
  // A Basis Universal level holds 16 bytes per 4 × 4 block, and the zstd frame says its own size.
  const std::uint64_t w = std::max<std::uint64_t>(1, texture.width >> level), h = std::max<std::uint64_t>(1, texture.height >> level);
  const unsigned long long framed = ZSTD_getFrameContentSize(l.bytes.data(), l.bytes.size());
  if (l.uncompressed_length > 16 * ((w + 3) / 4) * ((h + 3) / 4) || framed != l.uncompressed_length) {
    return Error{name, "KTX2 level " + std::to_string(level) + " declares a length its size or its zstd frame does not have"};
  }
  std::vector<unsigned char> out(l.uncompressed_length);
  const std::size_t made = ZSTD_decompress(out.data(), out.size(), l.bytes.data(), l.bytes.size());
  if (ZSTD_isError(made) || made != out.size()) {
    return Error{name, "KTX2 level " + std::to_string(level) + " does not inflate (zstd) to its declared length"};
  }
  return out;
}

std::vector<std::uint32_t> uastc_descriptor(std::uint8_t transfer, std::uint8_t channel, bool supercompressed) {
  constexpr std::uint32_t kBlockBytes = 24 + 16;  // the basic block and one sample
  return {
      4 + kBlockBytes,                                       // dfdTotalSize
      0,                                                     // vendor Khronos, basic descriptor type
      2u | (kBlockBytes << 16),                              // version 2, block size
      kModelUASTC | (std::uint32_t(primaries_for(transfer)) << 8) | (std::uint32_t(transfer) << 16),  // straight alpha
      3u | (3u << 8),                                        // 4 × 4 texel blocks
      supercompressed ? 0u : std::uint32_t(kUastcBlockBytes),  // bytesPlane0
      0,
      (127u << 16) | (std::uint32_t(channel) << 24),         // bit offset 0, 128 bits
      0,                                                     // sample position
      0,                                                     // sampleLower
      0xFFFFFFFFu,                                           // sampleUpper
  };
}

Status conform_primaries(std::vector<unsigned char>& file, const std::string& name) {
  const auto texture = read(file, name);
  if (!texture) return texture.error();
  // The DFD's fourth word (after its total size and the block header): model, primaries, transfer.
  file[u32_at(file, 48) + 12 + 1] = primaries_for(texture->descriptor.transfer);
  return success();
}

Result<Level> uastc_level(std::vector<unsigned char> blocks, int zstd_level) {
  Level level;
  level.uncompressed_length = blocks.size();
  if (zstd_level <= 0) {
    level.bytes = std::move(blocks);
    return level;
  }
  level.bytes.resize(ZSTD_compressBound(blocks.size()));
  const std::size_t made = ZSTD_compress(level.bytes.data(), level.bytes.size(), blocks.data(), blocks.size(), zstd_level);
  if (ZSTD_isError(made)) return Error{"", std::string("zstd: ") + ZSTD_getErrorName(made)};
  level.bytes.resize(made);
  return level;
}

Result<std::vector<unsigned char>> write_uastc(const UastcFile& file) {
  const std::size_t count = file.levels.size();
  if (count == 0 || count > kMaxLevels) return Error{"", "a KTX2 file of " + std::to_string(count) + " levels"};
  const bool zstd = file.zstd;
  std::vector<unsigned char> kvd;
  const std::string entry = std::string("KTXwriter") + '\0' + file.writer + '\0';
  append_u32(kvd, std::uint32_t(entry.size()));
  kvd.insert(kvd.end(), entry.begin(), entry.end());
  kvd.resize(aligned(kvd.size(), 4));
  const std::vector<std::uint32_t> dfd = uastc_descriptor(file.transfer, file.channel, zstd);

  std::vector<unsigned char> out(kHeaderBytes + count * kLevelIndexEntryBytes);
  std::memcpy(out.data(), kIdentifier, sizeof kIdentifier);
  const std::uint32_t header[9] = {0, 1, file.width, file.height, 0, 0, 1, std::uint32_t(count),
                                   zstd ? std::uint32_t(kSupercompressionZstd) : std::uint32_t(kSupercompressionNone)};
  for (std::size_t i = 0; i < 9; ++i) put_u32(out, 12 + 4 * i, header[i]);
  put_u32(out, 48, std::uint32_t(out.size()));
  put_u32(out, 52, std::uint32_t(dfd.size() * 4));
  for (std::uint32_t w : dfd) append_u32(out, w);
  put_u32(out, 56, std::uint32_t(out.size()));
  put_u32(out, 60, std::uint32_t(kvd.size()));
  out.insert(out.end(), kvd.begin(), kvd.end());
  // sgdByteOffset and sgdByteLength stay 0: UASTC has no global data.
  const std::size_t alignment = zstd ? 1 : kUastcBlockBytes;
  for (std::size_t l = count; l-- > 0;) {
    out.resize(aligned(out.size(), alignment));
    const std::size_t entry_at = kHeaderBytes + l * kLevelIndexEntryBytes;
    put_u64(out, entry_at, out.size());
    const Level& level = file.levels[l];
    put_u64(out, entry_at + 8, level.bytes.size());
    put_u64(out, entry_at + 16, level.uncompressed_length);
    out.insert(out.end(), level.bytes.begin(), level.bytes.end());
  }
  return out;
}

}  // namespace matbake::ktx2
