#pragma once
// PSNR of two renders over what either shows, for the runtime tests and the bake bench (no GoogleTest).
#include <filesystem>

namespace matbake::test {

// PSNR (dB) of render `test` against `reference` over the pixels where either is not the
// background (the top-left pixel of the reference): 8-bit RGB, peak 255. Infinity when equal.
// Throws std::runtime_error when either cannot be read or their sizes differ.
double render_psnr(const std::filesystem::path& reference, const std::filesystem::path& test);

}  // namespace matbake::test
