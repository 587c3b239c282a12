#include "matbake/ocio.hpp"

#include <OpenColorIO/OpenColorIO.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdlib>
#include <sstream>

namespace OCIO = OCIO_NAMESPACE;

namespace matbake::color {

extern const char* const default_ocio_config;

struct OcioConfig::Impl {
  OCIO::ConstConfigRcPtr config;
  std::string source;
};

struct OcioProcessor::Impl {
  OCIO::ConstCPUProcessorRcPtr float_path;
  OCIO::ConstCPUProcessorRcPtr u8_to_float_path;
};

namespace {

// OCIO's messages can span lines; matbake's errors are one line.
std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

Result<OcioConfig> validated(OCIO::ConstConfigRcPtr config, std::string source) {
  try {
    config->validate();
  } catch (const OCIO::Exception& e) {
    return Error{source, "invalid OCIO config: " + first_line(e.what())};
  }
  return OcioConfig(std::make_shared<const OcioConfig::Impl>(OcioConfig::Impl{std::move(config), std::move(source)}));
}

constexpr std::size_t kPixelsPerTask = 16384;  // scheduling costs nothing next to the work

}  // namespace

Result<OcioConfig> OcioConfig::load_builtin() {
  try {
    std::istringstream text(default_ocio_config);
    return validated(OCIO::Config::CreateFromStream(text), "built-in");
  } catch (const OCIO::Exception& e) {
    return Error{"built-in OCIO config", first_line(e.what())};
  }
}

Result<OcioConfig> OcioConfig::load(const std::filesystem::path& path) {
  std::string file = path.string();
  if (file.empty()) {
    const char* env = std::getenv("OCIO");
    if (env == nullptr || *env == '\0') return load_builtin();
    file = env;
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return Error{file, "OCIO config not found"};
  try {
    return validated(OCIO::Config::CreateFromFile(file.c_str()), file);
  } catch (const OCIO::Exception& e) {
    return Error{file, "cannot load OCIO config: " + first_line(e.what())};
  }
}

const std::string& OcioConfig::source() const { return impl_->source; }

bool OcioConfig::has_colorspace(std::string_view name) const {
  return impl_->config->getColorSpace(std::string(name).c_str()) != nullptr;
}

bool OcioConfig::is_scene_linear(std::string_view name) const {
  const auto space = impl_->config->getColorSpace(std::string(name).c_str());
  const auto scene_linear = impl_->config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
  if (space == nullptr) return false;
  return std::string_view(space->getEncoding()) == "scene-linear" ||
         (scene_linear != nullptr && std::string_view(space->getName()) == scene_linear->getName());
}

std::vector<std::string> OcioConfig::colorspace_names() const {
  std::vector<std::string> names;
  const auto& config = *impl_->config;
  for (int i = 0; i < config.getNumColorSpaces(); ++i) names.emplace_back(config.getColorSpaceNameByIndex(i));
  return names;
}

Result<OcioProcessor> OcioConfig::processor(std::string_view from, std::string_view to) const {
  for (std::string_view name : {from, to}) {
    if (!has_colorspace(name)) {
      return Error{impl_->source, "OCIO config has no colour space '" + std::string(name) + "'"};
    }
  }
  try {
    const auto processor = impl_->config->getProcessor(std::string(from).c_str(), std::string(to).c_str());
    return OcioProcessor(std::make_shared<const OcioProcessor::Impl>(OcioProcessor::Impl{
        processor->getDefaultCPUProcessor(),
        processor->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_UINT8, OCIO::BIT_DEPTH_F32,
                                            OCIO::OPTIMIZATION_DEFAULT)}));
  } catch (const OCIO::Exception& e) {
    return Error{impl_->source, "cannot convert '" + std::string(from) + "' to '" + std::string(to) +
                                    "': " + first_line(e.what())};
  }
}

void OcioProcessor::apply(std::span<float> pixels, int channels) const {
  // A CPUProcessor is safe to share between threads; OCIO itself applies on one.
  const std::size_t count = pixels.size() / channels;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kPixelsPerTask), [&](const auto& r) {
    OCIO::PackedImageDesc desc(pixels.data() + r.begin() * channels, long(r.size()), 1, channels);
    impl_->float_path->apply(desc);
  });
}

void OcioProcessor::apply(std::span<const uint8_t> in, std::span<float> out, int channels) const {
  const std::size_t count = in.size() / channels;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kPixelsPerTask), [&](const auto& r) {
    const std::ptrdiff_t x_in = channels, x_out = channels * std::ptrdiff_t(sizeof(float));
    OCIO::PackedImageDesc src(const_cast<uint8_t*>(in.data()) + r.begin() * channels, long(r.size()), 1,
                              channels, OCIO::BIT_DEPTH_UINT8, 1, x_in, x_in * long(r.size()));
    OCIO::PackedImageDesc dst(out.data() + r.begin() * channels, long(r.size()), 1, channels,
                              OCIO::BIT_DEPTH_F32, sizeof(float), x_out, x_out * long(r.size()));
    impl_->u8_to_float_path->apply(src, dst);
  });
}

}  // namespace matbake::color
