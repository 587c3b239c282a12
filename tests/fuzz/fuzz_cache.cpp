// The caches a build keeps in OUT/.matbake, as anyone who can write there leaves them: the input's
// bytes as an encode-cache entry (delivery/encode_cache: a KTX2, PNG or WebP file behind a header of
// counts and error figures), read for a 4 × 4 texture, and as the bake's kept-map index
// (bake/map_cache: maps.json), read for a map and a trace's counts. Nothing may throw or crash, an
// entry is used only as a file of the asked size, and a kept map only with the floats it must have.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "lib/src/bake/map_cache.hpp"
#include "lib/src/delivery/encode_cache.hpp"

namespace fs = std::filesystem;
using namespace matbake;

namespace {

const fs::path& folder() {
  static const fs::path f = [] {
    const fs::path base = fs::temp_directory_path() / ("matbake-fuzz-cache-" + std::to_string(getpid()));
    fs::create_directories(base);
    return base;
  }();
  return f;
}

void write(const fs::path& file, const std::uint8_t* data, std::size_t size) {
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
}

constexpr const char* kKey = "0123456789abcdef0123456789abcdef";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  write(folder() / (std::string(kKey) + ".ktx2e"), data, size);
  const delivery::EncodeCache cache{folder(), 1u << 30};
  bool reused = false;
  const auto found = delivery::through_cache(cache, kKey, {4, 4}, [] { return Result<delivery::Encoded>(Error{"", "not encoded"}); }, reused);
  if (reused && (!found || found->file.empty() || found->levels < 1)) std::abort();

  write(folder() / "maps.json", data, size);
  const auto kept = bake::load_map(folder(), bake::Map::height, "k", 1, 4, 4);
  if (kept && (kept->images.size() != 1 || kept->images[0].values.size() != 16)) std::abort();
  const auto counts = bake::load_trace(folder(), "k", 1);
  if (counts && counts->textures.size() != 1) std::abort();
  return 0;
}
