#pragma once
// Basis Universal's `basisu`, run as a separate program (not linked): found as MATBAKE_BASISU or on
// PATH, its version read once from `basisu -version`.
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

// Runs the encoder with `args`, its output into `log` (a scratch file). A failure (a non-zero exit,
// a signal) is an error naming `what`, with the encoder's own error line.
Status run_encoder(const Encoder& encoder, const std::vector<std::string>& args, const std::filesystem::path& log,
                   const std::string& what);

}  // namespace matbake::delivery
