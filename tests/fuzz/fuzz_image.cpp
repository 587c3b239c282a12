// Image decoding through matbake's reader (OIIO behind RowReader): any bytes, any claimed size.
// The format is picked from the leading bytes, as a file's extension would pick it.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include <OpenEXR/openexr_base.h>
#include <OpenImageIO/imageio.h>

#include "matbake/image.hpp"

namespace {

const char* name_for(const std::uint8_t* data, std::size_t size) {
  const auto starts = [&](const char* magic, std::size_t n) { return size >= n && std::memcmp(data, magic, n) == 0; };
  if (starts("\x76\x2f\x31\x01", 4)) return "fuzz.exr";
  if (starts("\xff\xd8", 2)) return "fuzz.jpg";
  if (starts("II*", 3) || starts("MM\0*", 4)) return "fuzz.tif";
  if (starts("#?", 2)) return "fuzz.hdr";
  return "fuzz.png";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Larger declared sizes stop at the header (the limit's own path); 128 × 128 keeps each decode
  // under ASan near a millisecond, so the run explores rather than decodes the largest seeds (the
  // reader's code paths do not depend on the size below a band of rows).
  matbake::image::set_max_pixels(std::uint64_t{1} << 14);
  // OpenEXR sizes its line buffers from the declared window while opening, before our limit sees
  // the size (under ASan each is cleared and quarantined). Windows above 1024 on a side are refused
  // here by the header check (OpenEXR's core: exr_header.cpp).
  exr_set_default_maximum_image_size(1024, 1024);
  exr_set_default_maximum_tile_size(1024, 1024);
  matbake::image::set_thread_count(1);
  // Only the reader the leading bytes name: after a failed open OIIO would otherwise try each of its
  // ~40 readers on every mutated input, and the run would measure them instead of ours.
  OIIO::attribute("try_all_readers", 0);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Both transfers, chosen by the last byte (one decode per input: the decode is the cost).
  const bool srgb = size > 0 && (data[size - 1] & 1) != 0;
  const auto colour = srgb ? matbake::color::Transfer::srgb : matbake::color::Transfer::linear;
  auto image = matbake::image::decode_image(std::span(data, size), name_for(data, size), colour);
  if (image && image->pixels.size() != image->sample_count()) __builtin_trap();  // a decoded image is whole
  return 0;
}
