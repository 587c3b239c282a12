#include "exr_header.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

namespace matbake::image {
namespace {

constexpr unsigned char kMagic[4] = {0x76, 0x2f, 0x31, 0x01};
constexpr std::uint32_t kMultipartFlag = 0x1000;  // bit 12 of the version field
constexpr std::size_t kMaxName = 256;             // long names (bit 10) are up to 255 bytes

std::uint32_t little_endian_u32(const unsigned char* bytes) {
  return std::uint32_t(bytes[0]) | std::uint32_t(bytes[1]) << 8 | std::uint32_t(bytes[2]) << 16 |
         std::uint32_t(bytes[3]) << 24;
}

}  // namespace

std::optional<std::string> exr_header_problem(OIIO::Filesystem::IOProxy& file) {
  const std::uint64_t size = file.size();
  unsigned char start[8];
  if (file.pread(start, sizeof start, 0) != sizeof start || std::memcmp(start, kMagic, sizeof kMagic) != 0) {
    return std::nullopt;
  }
  const bool multipart = (little_endian_u32(start + 4) & kMultipartFlag) != 0;
  // One attribute: name\0 type\0 int32 size, then `size` bytes. An empty name ends a header; a
  // multi-part file has one header per part and an empty header after the last.
  std::array<unsigned char, 2 * kMaxName + 4> record;
  std::uint64_t at = sizeof start;
  for (bool header_empty = false; !header_empty;) {
    header_empty = true;
    for (;;) {
      const std::uint64_t left = size - std::min(at, size);
      const std::size_t got = file.pread(record.data(), std::size_t(std::min<std::uint64_t>(record.size(), left)),
                                         std::int64_t(at));
      const auto* name_end = static_cast<const unsigned char*>(std::memchr(record.data(), 0, std::min(got, kMaxName)));
      if (name_end == nullptr) return std::nullopt;  // truncated or malformed: the reader says so
      if (name_end == record.data()) {
        at += 1;
        break;
      }
      header_empty = false;
      const std::size_t type_at = std::size_t(name_end - record.data()) + 1;
      const auto* type_end =
          static_cast<const unsigned char*>(std::memchr(record.data() + type_at, 0, std::min(got - type_at, kMaxName)));
      if (type_end == nullptr) return std::nullopt;
      const std::size_t size_at = std::size_t(type_end - record.data()) + 1;
      if (got < size_at + 4) return std::nullopt;
      const std::int32_t declared = std::int32_t(little_endian_u32(record.data() + size_at));
      at += size_at + 4;
      if (declared < 0 || std::uint64_t(declared) > size - at) {
        const std::string name(reinterpret_cast<const char*>(record.data()), type_at - 1);
        return "its OpenEXR header's attribute '" + name + "' declares " + std::to_string(declared) +
               " bytes, more than the " + std::to_string(size - at) + " that follow it";
      }
      at += std::uint64_t(declared);
    }
    if (!multipart) break;
  }
  return std::nullopt;
}

}  // namespace matbake::image
