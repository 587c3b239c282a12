#pragma once
// Basis Universal's `basisu`, run as a separate program (not linked): found as MATBAKE_BASISU or on
// PATH, its version read once from `basisu -version`.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "matbake/result.hpp"

namespace matbake::delivery {

struct Encoder {
  std::filesystem::path program;
  std::string version;  // "1.16.4"
};

// MATBAKE_BASISU when set (what it names must run), else `basisu` on PATH; the error says how to
// install it (scripts/install-basisu.sh) when there is none.
Result<Encoder> find_encoder();

// Runs the encoder with `args` on `texels` texels (all the levels it is given), supervised
// (subprocess.hpp) with a time limit derived from them (encode_time_limit). A failure (a non-zero
// exit, a signal, the time limit) is an error naming `what`, with the encoder's own error line. It
// runs in `folder` when one is given (-unpack writes its files where it runs).
Status run_encoder(const Encoder& encoder, const std::vector<std::string>& args, const std::string& what, std::uint64_t texels,
                   const std::filesystem::path& folder = {});

// A minute plus 10 µs a texel; MATBAKE_ENCODER_TIME_LIMIT (seconds) replaces it.
std::chrono::milliseconds encode_time_limit(std::uint64_t texels);

}  // namespace matbake::delivery
