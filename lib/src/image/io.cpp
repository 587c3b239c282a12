// All image file I/O goes through OpenImageIO here, and only here.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "matbake/atomic_file.hpp"
#include "matbake/image.hpp"
#include "matbake/pixels.hpp"

namespace fs = std::filesystem;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace matbake::image {
namespace {

std::string first_line(const std::string& text) {
  const std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "unknown error" : line;
}

SampleType stored_type_of(const ImageSpec& spec) {
  switch (spec.format.basetype) {
    case TypeDesc::UINT8: return SampleType::u8;
    case TypeDesc::UINT16: return SampleType::u16;
    case TypeDesc::HALF: return SampleType::half;
    default: return SampleType::f32;  // float, double and other integer widths read as float
  }
}

TypeDesc type_desc(SampleType type) {
  switch (type) {
    case SampleType::u8: return TypeDesc::UINT8;
    case SampleType::u16: return TypeDesc::UINT16;
    case SampleType::half: return TypeDesc::HALF;
    case SampleType::f32: return TypeDesc::FLOAT;
  }
  return TypeDesc::FLOAT;
}

template <class T>
Status read_samples(OIIO::ImageInput& in, const ImageSpec& spec, SampleType type, std::vector<T>& samples,
                    const fs::path& path) {
  samples.resize(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!in.read_image(0, 0, 0, spec.nchannels, type_desc(type), samples.data())) {
    return Error{path.string(), "cannot read pixels: " + first_line(in.geterror())};
  }
  return success();
}

// Non-finite samples are rejected before decoding (they are bad input, not something to convert),
// and so are finite ones that the decode overflows (sRGB/gamma 2.2 of values above about 1e16).
struct NonFinite {
  std::size_t nan = 0;
  std::size_t inf = 0;
};

NonFinite count_non_finite(std::span<const float> samples) {
  NonFinite n;
  for (float v : samples) {
    n.nan += std::isnan(v);
    n.inf += std::isinf(v);
  }
  return n;
}

NonFinite count_non_finite_half(std::span<const uint16_t> bits) {
  constexpr uint16_t kExponent = 0x7c00, kMantissa = 0x03ff;  // all-ones exponent: Inf or NaN
  NonFinite n;
  for (uint16_t b : bits) {
    const bool special = (b & kExponent) == kExponent;
    n.nan += special && (b & kMantissa) != 0;
    n.inf += special && (b & kMantissa) == 0;
  }
  return n;
}

Status reject_non_finite(NonFinite n, const std::string& what, const fs::path& path) {
  if (n.nan == 0 && n.inf == 0) return success();
  return Error{path.string(), what + std::to_string(n.nan) + " NaN and " + std::to_string(n.inf) +
                                  " Inf samples; matbake rejects non-finite texels"};
}

}  // namespace

std::optional<SampleType> sample_type_from_name(std::string_view name) {
  if (name == "8") return SampleType::u8;
  if (name == "16") return SampleType::u16;
  if (name == "half") return SampleType::half;
  if (name == "float") return SampleType::f32;
  return std::nullopt;
}

std::string_view sample_type_name(SampleType type) {
  switch (type) {
    case SampleType::u8: return "8";
    case SampleType::u16: return "16";
    case SampleType::half: return "half";
    case SampleType::f32: return "float";
  }
  return "?";
}

bool is_integer(SampleType type) { return type == SampleType::u8 || type == SampleType::u16; }

std::vector<color::Transfer> channel_transfers(const Image& image, color::Transfer colour) {
  std::vector<color::Transfer> transfers(std::size_t(image.channels), colour);
  if (image.alpha_channel >= 0 && image.alpha_channel < image.channels) {
    transfers[image.alpha_channel] = color::Transfer::linear;
  }
  return transfers;
}

void set_thread_count(int threads) { OIIO::attribute("threads", threads); }

Result<Image> read_image(const fs::path& path, color::Transfer colour, ReadInfo* info) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return Error{path.string(), "no such file"};
  if (fs::is_directory(path, ec)) return Error{path.string(), "is a folder, not an image"};

  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  if (!in) return Error{path.string(), "not a readable image: " + first_line(OIIO::geterror())};
  const ImageSpec spec = in->spec();
  if (spec.nchannels < 1 || spec.nchannels > 4) {
    return Error{path.string(), std::to_string(spec.nchannels) +
                                    " channels; matbake reads 1 to 4 (gray, gray+alpha, RGB, RGBA)"};
  }
  if (spec.depth > 1) return Error{path.string(), "volume images are not supported"};

  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.nchannels;
  image.channel_names = spec.channelnames;
  image.alpha_channel = spec.alpha_channel;
  image.pixels.resize(image.sample_count());
  const std::vector<color::Transfer> transfers = channel_transfers(image, colour);

  const SampleType stored = stored_type_of(spec);
  if (info != nullptr) *info = ReadInfo{stored, in->format_name()};
  switch (stored) {
    case SampleType::u8: {
      std::vector<uint8_t> samples;
      if (Status s = read_samples(*in, spec, stored, samples, path); !s) return s.error();
      color::decode_pixels(std::span<const uint8_t>(samples), image.pixels, transfers);
      break;
    }
    case SampleType::u16: {
      std::vector<uint16_t> samples;
      if (Status s = read_samples(*in, spec, stored, samples, path); !s) return s.error();
      color::decode_pixels(std::span<const uint16_t>(samples), image.pixels, transfers);
      break;
    }
    case SampleType::half: {
      std::vector<uint16_t> samples;  // half bit patterns, decoded by table
      if (Status s = read_samples(*in, spec, stored, samples, path); !s) return s.error();
      if (Status s = reject_non_finite(count_non_finite_half(samples), "contains ", path); !s) return s.error();
      color::decode_half_pixels(samples, image.pixels, transfers);
      break;
    }
    case SampleType::f32: {
      std::vector<float> samples;
      if (Status s = read_samples(*in, spec, stored, samples, path); !s) return s.error();
      if (Status s = reject_non_finite(count_non_finite(samples), "contains ", path); !s) return s.error();
      color::decode_pixels(std::span<const float>(samples), image.pixels, transfers);
      break;
    }
  }
  if (colour != color::Transfer::linear) {
    const std::size_t overflow = count_non_finite(image.pixels).inf;
    if (overflow > 0) {
      return Error{path.string(), std::to_string(overflow) + " samples overflow float when decoded from " +
                                      std::string(color::transfer_name(colour)) + " (inputs above about 1e16)"};
    }
  }
  return image;
}

Status write_image(const Image& image, const fs::path& path, const WriteOptions& options) {
  if (image.channels < 1 || image.channels > 4 || image.pixels.size() != image.sample_count()) {
    return Error{path.string(), "internal: inconsistent image"};
  }
  auto file = AtomicFile::create(path);
  if (!file) return file.error();

  auto out = OIIO::ImageOutput::create(file->temp_path().string());
  if (!out) return Error{path.string(), "no image writer for this extension: " + first_line(OIIO::geterror())};

  ImageSpec spec(image.width, image.height, image.channels, type_desc(options.type));
  if (image.channel_names.size() == std::size_t(image.channels)) spec.channelnames = image.channel_names;
  spec.alpha_channel = image.alpha_channel;
  spec.attribute("oiio:UnassociatedAlpha", 1);  // write colour as given, never divided by alpha
  if (!options.colorspace.empty()) spec.attribute("oiio:ColorSpace", options.colorspace);
  std::string compression = options.compression;
  if (compression.empty() && std::string_view(out->format_name()) == "openexr") compression = "zip";
  if (!compression.empty()) spec.attribute("compression", compression);

  if (!out->open(file->temp_path().string(), spec)) {
    return Error{path.string(), "cannot write: " + first_line(out->geterror())};
  }
  const std::vector<color::Transfer> transfers = channel_transfers(image, options.colour);
  bool written = false;
  switch (options.type) {
    case SampleType::u8: {
      std::vector<uint8_t> samples(image.pixels.size());
      color::encode_pixels(image.pixels, samples, transfers);
      written = out->write_image(TypeDesc::UINT8, samples.data());
      break;
    }
    case SampleType::u16: {
      std::vector<uint16_t> samples(image.pixels.size());
      color::encode_pixels(image.pixels, samples, transfers);
      written = out->write_image(TypeDesc::UINT16, samples.data());
      break;
    }
    case SampleType::half:
    case SampleType::f32: {
      // OIIO rounds float to half to nearest even.
      std::vector<float> samples(image.pixels.size());
      color::encode_pixels(std::span<const float>(image.pixels), samples, transfers);
      if (options.type == SampleType::half) {
        // Finite values from 65520 on would round to Inf: refuse rather than write non-finite texels.
        constexpr float kHalfOverflow = 65520.0f;
        const auto beyond = std::count_if(samples.begin(), samples.end(),
                                          [](float v) { return std::abs(v) >= kHalfOverflow; });
        if (beyond > 0) {
          return Error{path.string(), std::to_string(beyond) +
                                          " samples exceed the half-float range (65504); use float samples"};
        }
      }
      written = out->write_image(TypeDesc::FLOAT, samples.data());
      break;
    }
  }
  if (!written || !out->close()) return Error{path.string(), "cannot write: " + first_line(out->geterror())};
  return file->commit();
}

}  // namespace matbake::image
