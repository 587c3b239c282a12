// The text formats matbake reads from users: the build manifest (TOML), a pack layout (JSON) and
// the material table (TOML). MATBAKE_FUZZ_FORMAT picks one (three targets).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "matbake/material_table.hpp"
#include "matbake/pack.hpp"
#include "matbake/pipeline.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
#if MATBAKE_FUZZ_FORMAT == 0
  (void)matbake::pipeline::parse_manifest(text, "fuzz/matbake.toml");
#elif MATBAKE_FUZZ_FORMAT == 1
  (void)matbake::pack::parse_layout(text, "fuzz-layout.json");
#else
  (void)matbake::material_table::parse_table(text, "fuzz-materials.toml");
#endif
  return 0;
}
