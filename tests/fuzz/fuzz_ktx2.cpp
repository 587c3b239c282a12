// The KTX2 reader (matbake reads basisu's files and its own): any bytes; every level it accepts is
// inflated, and a level's declared length is bounded before anything is allocated for it.
#include <cstddef>
#include <cstdint>
#include <span>

#include "matbake/image.hpp"
#include "matbake/ktx2.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  matbake::image::set_max_pixels(std::uint64_t{1} << 20);  // levels of at most 1 MB: the run explores
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto texture = matbake::ktx2::read(std::span(data, size), "fuzz.ktx2");
  if (!texture) return 0;
  for (std::size_t l = 0; l < texture->levels.size(); ++l) {
    auto level = matbake::ktx2::level_data(*texture, l, "fuzz.ktx2");
    if (level && texture->supercompression == matbake::ktx2::kSupercompressionZstd &&
        level->size() != texture->levels[l].uncompressed_length) {
      __builtin_trap();  // an inflated level is its declared length
    }
  }
  return 0;
}
