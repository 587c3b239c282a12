#pragma once
// The KTX 2.0 container (Khronos KTX File Format Specification 2.0) as matbake writes and reads it:
// 2D textures with a mip chain, Basis Universal payloads (ETC1S/BasisLZ or UASTC, optionally zstd-
// supercompressed). Every offset and length is checked against the file before it is used.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "matbake/result.hpp"

namespace matbake::ktx2 {

enum : std::uint32_t { kSupercompressionNone = 0, kSupercompressionBasisLZ = 1, kSupercompressionZstd = 2 };
enum : std::uint8_t { kModelETC1S = 163, kModelUASTC = 166 };
enum : std::uint8_t { kTransferLinear = 1, kTransferSRGB = 2 };
enum : std::uint8_t { kPrimariesUnspecified = 0, kPrimariesBT709 = 1 };

// KHR_texture_basisu's colour primaries for a transfer: BT.709 for colour (sRGB transfer), none
// (unspecified) for non-colour data (linear: normal, occlusion, metallic-roughness); three.js then
// gives data textures no colour space rather than linear sRGB.
constexpr std::uint8_t primaries_for(std::uint8_t transfer) {
  return transfer == kTransferSRGB ? kPrimariesBT709 : kPrimariesUnspecified;
}
// The channel id of a UASTC sample (KHR_DF_CHANNEL_UASTC_*): what the block holds.
enum : std::uint8_t { kUastcRGB = 0, kUastcRGBA = 3, kUastcRRR = 4, kUastcRRRG = 5, kUastcRG = 6 };

// The fields of the basic data format descriptor block that tell what a texture holds.
struct Descriptor {
  std::uint8_t model = 0, primaries = 0, transfer = 0, flags = 0;
  std::uint8_t block_width = 1, block_height = 1;  // texel block, in texels
  std::uint8_t bytes_plane0 = 0;
  std::vector<std::uint8_t> channels;              // each sample's channel id, in order
};

struct Level {
  std::vector<unsigned char> bytes;  // as stored (supercompressed when the file is); none from read_header
  std::uint64_t byte_length = 0;     // as the level index says
  std::uint64_t uncompressed_length = 0;
};

struct Texture {
  std::uint32_t vk_format = 0;  // VK_FORMAT_UNDEFINED for Basis Universal
  std::uint32_t type_size = 1;
  std::uint32_t width = 0, height = 0;
  std::uint32_t supercompression = kSupercompressionNone;
  Descriptor descriptor;
  std::vector<std::uint32_t> dfd;  // the descriptor as stored (its total size first)
  std::vector<std::pair<std::string, std::string>> key_values;  // value without its terminating NUL
  std::vector<unsigned char> global_data;                       // BasisLZ's codebooks
  std::vector<Level> levels;                                     // level 0 (the largest) first
};

// A 2D KTX2 file read: header, level index, DFD, key/value pairs, global data. Errors name `name`.
Result<Texture> read(std::span<const unsigned char> bytes, const std::string& name);

// How many leading bytes of a KTX2 file read_header needs (header, level index, DFD, key/value
// data, global data), from its first kHeaderBytes; 0 when they are not a KTX2 header.
inline constexpr std::size_t kHeaderBytes = 80;
std::uint64_t header_extent(std::span<const unsigned char> first);
// As read, from the file's first header_extent bytes and its size, without its levels' bytes (each
// level's place checked against `file_size`): what inspect needs, whatever the file's size.
Result<Texture> read_header(std::span<const unsigned char> head, std::uint64_t file_size, const std::string& name);

// The DFD of a UASTC texture: one 128-bit sample of `channel`, sRGB or linear transfer with its
// primaries_for; bytesPlane0 16 unless zstd-supercompressed (then 0, as the specification asks).
std::vector<std::uint32_t> uastc_descriptor(std::uint8_t transfer, std::uint8_t channel, bool supercompressed);

// A level of raw UASTC blocks as a file stores it: supercompressed with zstd at `zstd_level` (1–22),
// or as it is when 0.
Result<Level> uastc_level(std::vector<unsigned char> blocks, int zstd_level);

// A UASTC texture of `levels` (uastc_level's, level 0 first, all supercompressed or none) as a KTX2
// file: levels aligned as the specification asks (16 bytes uncompressed), smallest level last in the
// index and first in the file. `writer` is KTXwriter's value.
struct UastcFile {
  std::uint32_t width = 0, height = 0;
  std::uint8_t transfer = kTransferSRGB, channel = kUastcRGB;
  std::vector<Level> levels;
  bool zstd = false;
  std::string writer;
};
Result<std::vector<unsigned char>> write_uastc(const UastcFile& file);

// Sets the DFD primaries of `file` (which `read` accepts) to primaries_for its transfer: basisu writes
// BT.709 for linear data too.
Status conform_primaries(std::vector<unsigned char>& file, const std::string& name);

// The uncompressed bytes of a level (zstd inflated; as stored otherwise; BasisLZ is not inflated).
Result<std::vector<unsigned char>> level_data(const Texture& texture, std::size_t level, const std::string& name);

}  // namespace matbake::ktx2
