#pragma once
// Bake test pairs made, not hand-picked: a glTF written again with each triangle primitive's
// indices simplified by meshoptimizer (borders locked), so that the low-poly keeps the original's
// vertices, UVs and materials.
#include <filesystem>

namespace matbake::test {

// Writes `output` (.glb) from `input` with each indexed or non-indexed triangle list cut to about
// `ratio` of its triangles; throws when a file cannot be read or written.
void write_simplified(const std::filesystem::path& input, const std::filesystem::path& output, double ratio);

}  // namespace matbake::test
