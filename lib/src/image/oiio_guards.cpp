// Two readers of OIIO 2.4 (Debian's 2.4.7) trust offsets taken from the file and read out of
// bounds; both were found by tests/fuzz/fuzz_image and both are fixed upstream in later releases.
#include "oiio_guards.hpp"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/span.h>

#include <algorithm>
#include <cstring>

#if OIIO_VERSION < OIIO_MAKE_VERSION(2, 5, 0)
OIIO_NAMESPACE_BEGIN

// OIIO's ICC profile decoder follows the offsets of text tags ('desc', 'cprt', mluc records) past
// the profile (SIGSEGV on a PNG with a damaged iCCP chunk, also reached from JPEG and TIFF). It
// only fills ICCProfile:* description attributes, which matbake never reads; the profile's bytes
// stay in the "ICCProfile" attribute, set by each reader before this call. The plug-ins call it
// through the PLT, and libmatbake comes before libOpenImageIO in the lookup order, so this
// definition replaces OIIO's (tests/unit/test_image.cpp checks that it is the one in effect). The
// declaration is OIIO's (tiffutils.h, which needs libtiff's headers).
bool decode_icc_profile(cspan<uint8_t> iccdata, ImageSpec& spec, std::string& error);
bool decode_icc_profile(cspan<uint8_t> /*iccdata*/, ImageSpec& /*spec*/, std::string& /*error*/) {
  return true;
}

OIIO_NAMESPACE_END
#endif

namespace matbake::image {

std::size_t CheckedMemReader::pread(void* buf, std::size_t size, std::int64_t offset) {
  const auto bytes = buffer();
  const auto length = std::int64_t(bytes.size());
  if (offset < 0 || offset >= length) return 0;
  size = std::min(size, std::size_t(length - offset));
  std::memcpy(buf, bytes.data() + offset, size);
  return size;
}

std::size_t CheckedMemReader::read(void* buf, std::size_t size) {
  const std::size_t got = pread(buf, size, m_pos);
  m_pos += std::int64_t(got);
  return got;
}

}  // namespace matbake::image
