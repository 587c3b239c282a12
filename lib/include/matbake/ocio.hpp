#pragma once
// OpenColorIO, wrapped: OCIO throws, this module returns matbake::Error instead, and no OCIO type
// leaks into other modules.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/result.hpp"

namespace matbake::color {

class OcioProcessor {
 public:
  // Converts interleaved RGB (channels = 3) or RGBA (channels = 4, alpha untouched) float pixels
  // in place.
  void apply(std::span<float> pixels, int channels) const;
  // OCIO's own 8-bit input path (it collapses to a lookup table); for benchmarks.
  void apply(std::span<const uint8_t> in, std::span<float> out, int channels) const;

  struct Impl;
  explicit OcioProcessor(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

 private:
  std::shared_ptr<const Impl> impl_;
};

class OcioConfig {
 public:
  // From `path`; when empty, from $OCIO when set; else the config shipped in
  // presets/ocio/config.ocio (compiled into the library).
  static Result<OcioConfig> load(const std::filesystem::path& path = {});
  static Result<OcioConfig> load_builtin();

  const std::string& source() const;  // the file it came from, or "built-in"
  bool has_colorspace(std::string_view name) const;
  bool is_scene_linear(std::string_view name) const;  // the scene_linear role or its encoding
  std::vector<std::string> colorspace_names() const;
  Result<OcioProcessor> processor(std::string_view from, std::string_view to) const;

  struct Impl;
  explicit OcioConfig(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

 private:
  std::shared_ptr<const Impl> impl_;
};

}  // namespace matbake::color
