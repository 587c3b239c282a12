#pragma once
// Images in memory are float, interleaved, linear (decoded at read, encoded at write) and keep
// alpha unassociated: OIIO is told so on both sides (../shared/design/DEBIAN-NOTES.md).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/color.hpp"
#include "matbake/result.hpp"

namespace matbake::image {

enum class SampleType { u8, u16, half, f32 };

std::optional<SampleType> sample_type_from_name(std::string_view name);  // "8", "16", "half", "float"
std::string_view sample_type_name(SampleType type);
bool is_integer(SampleType type);

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;                        // 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA
  std::vector<std::string> channel_names;  // as stored ("R", "G", "B", "A", "Y", ...)
  int alpha_channel = -1;                  // index into channels, or -1
  std::vector<float> pixels;               // width * height * channels, row-major, interleaved

  std::size_t sample_count() const {
    return std::size_t(width) * std::size_t(height) * std::size_t(channels);
  }
};

// Per-channel transfers: `colour` for colour channels, linear for alpha.
std::vector<color::Transfer> channel_transfers(const Image& image, color::Transfer colour);

struct ReadInfo {
  SampleType stored_type = SampleType::u8;  // the closest of ours to what the file holds
  std::string format_name;                  // OIIO's name: "png", "openexr", "tiff", "jpeg", ...
};

// Reads any image OIIO can and decodes colour channels with `colour` (alpha stays linear).
// Errors: missing or unreadable file, 0 or more than 4 channels, NaN or Inf samples (counted),
// and finite samples that overflow float when decoded.
Result<Image> read_image(const std::filesystem::path& path, color::Transfer colour,
                         ReadInfo* info = nullptr);

struct WriteOptions {
  color::Transfer colour = color::Transfer::linear;  // applied to colour channels, never alpha
  SampleType type = SampleType::half;
  std::string compression;  // OIIO "compression" attribute; empty: "zip" for EXR, else default
  std::string colorspace;   // written as oiio:ColorSpace when not empty
};

// Writes atomically: a temporary file in the target folder, renamed over `path` when complete.
// The format follows the extension. Output bytes depend only on the inputs (no timestamps).
Status write_image(const Image& image, const std::filesystem::path& path, const WriteOptions& options);

// Threads OIIO may use (EXR compression above all); 0: one per core.
void set_thread_count(int threads);

}  // namespace matbake::image
