#pragma once
// Test inputs written, and outputs read back, with OIIO directly and with alpha unassociated, so
// the tests see the stored samples themselves rather than matbake's view of them.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace matbake::test {

// The bundled examples of this source tree.
inline const std::filesystem::path kExamples = std::filesystem::path(MATBAKE_SOURCE_DIR) / "examples";

// The bundled example copied into `dir` (the manifest's output then goes to dir/out), optionally
// with its AO samples lowered to keep the test quick.
void copy_example(const std::filesystem::path& dir, bool few_samples = false);

struct RawImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::string format;  // "uint8", "uint16", "half", "float"
  std::vector<std::string> channel_names;
  std::vector<double> samples;  // stored values: codes for integer formats, values for float ones
};

// Writes samples as given (codes for integer formats). channel_names may be empty.
void write_raw(const std::filesystem::path& path, int width, int height, int channels, const std::string& format,
               const std::vector<double>& samples, std::vector<std::string> channel_names = {});
RawImage read_raw(const std::filesystem::path& path);

std::string read_bytes(const std::filesystem::path& path);
void write_bytes(const std::filesystem::path& path, const std::string& bytes);

// Names in `folder`, sorted: to check that nothing (temporary files included) was left behind.
std::vector<std::string> list_folder(const std::filesystem::path& folder);

}  // namespace matbake::test
