// OpenImageIO's readers and writers, and its resize, behind oiio_module.hpp: every format that
// matbake does not read or write itself. Built as the module libmatbake_oiio.so, which
// libmatbake loads on first need.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cstring>

#include "../oiio_module.hpp"
#include "checked_mem_reader.hpp"
#include "exr_header.hpp"

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

// EXR holds linear light by definition; a TIFF's colour space as OIIO reads it from the file.
// Other formats' oiio:ColorSpace is OIIO's default, not the file's word (JPEG is always "sRGB").
void declared_transfer(const ImageSpec& spec, StoredFormat& format) {
  if (format.format_name == "openexr") {
    format.tagged = color::Transfer::linear;
    format.tag = "OpenEXR (linear)";
    return;
  }
  if (format.format_name != "tiff") return;
  const std::string space = spec.get_string_attribute("oiio:ColorSpace");
  if (space == "sRGB") format.tagged = color::Transfer::srgb;
  else if (space == "Linear" || space == "linear") format.tagged = color::Transfer::linear;
  else if (space == "Gamma2.2") format.tagged = color::Transfer::gamma22;
  if (format.tagged) format.tag = "TIFF colour space " + space;
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

// Refuses an OpenEXR file whose header OpenEXR's C core refuses (exr_header.hpp), judged by
// content as OIIO's readers are, whatever the name.
Status check_exr_header(const fs::path& path, OIIO::Filesystem::IOProxy* proxy) {
  std::optional<std::string> problem;
  if (proxy != nullptr) {
    problem = exr_header_problem(*proxy);
  } else {
    OIIO::Filesystem::IOFile file(path.string(), OIIO::Filesystem::IOProxy::Read);
    if (file.opened()) problem = exr_header_problem(file);
  }
  if (problem) return Error{path.string(), "not a readable image: OpenEXR header: " + *problem};
  return success();
}

class OiioReader final : public StoredReader {
 public:
  static Result<std::unique_ptr<StoredReader>> open(const fs::path& path, std::span<const unsigned char> memory) {
    auto reader = std::unique_ptr<OiioReader>(new OiioReader(path));
    if (!memory.empty()) reader->proxy_ = std::make_unique<CheckedMemReader>(memory.data(), memory.size());
    OIIO::Filesystem::IOProxy* proxy = reader->proxy_.get();
    ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    // The readers of OIIO 2.4 look for the proxy in the configuration hint.
    if (proxy) config.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy);
    if (Status s = check_exr_header(path, proxy); !s) return s.error();
    reader->in_ = OIIO::ImageInput::open(path.string(), &config, proxy);
    if (!reader->in_) return Error{path.string(), "not a readable image: " + first_line(OIIO::geterror())};
    const ImageSpec& spec = reader->in_->spec();
    if (spec.depth > 1) return Error{path.string(), "volume images are not supported"};
    StoredFormat& format = reader->format_;
    format.layout.width = spec.width;
    format.layout.height = spec.height;
    format.layout.channels = spec.nchannels;
    format.layout.channel_names = spec.channelnames;
    format.layout.alpha_channel = spec.alpha_channel;
    format.stored = stored_type_of(spec);
    format.format_name = reader->in_->format_name();
    declared_transfer(spec, format);
    return std::unique_ptr<StoredReader>(std::move(reader));
  }

  // Tiled files (mip-mapped EXR, TIFF) are read whole at level 0 on the first call: OIIO 2.4's
  // read_scanlines on them can divide by zero (SIGFPE), and read_tiles wants tile-aligned bands.
  Status read(int y, int rows, void* samples) override {
    const ImageSpec& spec = in_->spec();
    if (spec.tile_width <= 0) {
      // Read as stored into our buffer: OIIO 2.4's read_scanlines allocates (and frees) a 64 MB
      // staging buffer on every call, even when no conversion is needed.
      const bool as_stored = spec.channelformats.empty() && spec.format == type_desc(format_.stored);
      const bool read = as_stored ? in_->read_native_scanlines(0, 0, spec.y + y, spec.y + y + rows, 0, samples)
                                  : read_converted(y, rows, samples);
      if (!read) return Error{path_.string(), "cannot read pixels: " + first_line(in_->geterror())};
      return success();
    }
    const std::size_t row_bytes = std::size_t(spec.width) * std::size_t(spec.nchannels) * type_desc(format_.stored).size();
    if (tiled_whole_.empty()) {
      tiled_whole_.resize(row_bytes * std::size_t(spec.height));
      if (!in_->read_image(0, 0, 0, spec.nchannels, type_desc(format_.stored), tiled_whole_.data())) {
        return Error{path_.string(), "cannot read pixels: " + first_line(in_->geterror())};
      }
    }
    std::memcpy(samples, tiled_whole_.data() + std::size_t(y) * row_bytes, std::size_t(rows) * row_bytes);
    return success();
  }

 private:
  explicit OiioReader(fs::path path) : path_(std::move(path)) {}

  // Files stored in another type (double, 32-bit integers) or in a type per channel (an EXR with
  // half colour and float depth) are read as stored, and each channel is converted into `samples`.
  bool read_converted(int y, int rows, void* samples) {
    const ImageSpec& spec = in_->spec();
    const std::size_t pixel_bytes = spec.pixel_bytes(true);
    stored_band_.resize(pixel_bytes * std::size_t(spec.width) * std::size_t(rows));
    if (!in_->read_native_scanlines(0, 0, spec.y + y, spec.y + y + rows, 0, stored_band_.data())) return false;
    const TypeDesc to = type_desc(format_.stored);
    const auto to_pixel = OIIO::stride_t(to.size()) * spec.nchannels;
    std::size_t offset = 0;
    for (int c = 0; c < spec.nchannels; ++c) {
      const TypeDesc from = spec.channelformat(c);
      if (!OIIO::convert_image(1, spec.width, rows, 1, stored_band_.data() + offset, from, OIIO::stride_t(pixel_bytes),
                               OIIO::stride_t(pixel_bytes) * spec.width, OIIO::AutoStride,
                               static_cast<char*>(samples) + std::size_t(c) * to.size(), to, to_pixel,
                               to_pixel * spec.width, OIIO::AutoStride)) {
        return false;
      }
      offset += from.size();
    }
    return true;
  }

  fs::path path_;
  std::unique_ptr<OIIO::Filesystem::IOProxy> proxy_;  // the bytes of an image in memory (declared first: outlives in_)
  std::unique_ptr<OIIO::ImageInput> in_;
  std::vector<std::byte> tiled_whole_;  // a tiled file's level 0, as stored
  std::vector<char> stored_band_;       // a band as stored, before read_converted converts it
};

class OiioWriter final : public StoredWriter {
 public:
  static Result<std::unique_ptr<StoredWriter>> open(const fs::path& path, const fs::path& written,
                                                    std::vector<unsigned char>* memory, const ImageLayout& layout,
                                                    const WriteOptions& options) {
    auto writer = std::unique_ptr<OiioWriter>(new OiioWriter(path));
    writer->out_ = OIIO::ImageOutput::create(written.string());
    if (!writer->out_) return Error{path.string(), "no image writer for this extension: " + first_line(OIIO::geterror())};
    if (memory) {
      writer->proxy_ = std::make_unique<OIIO::Filesystem::IOVecOutput>(*memory);
      if (!writer->out_->set_ioproxy(writer->proxy_.get())) {
        return Error{path.string(), "this format cannot be written to memory"};
      }
    }
    ImageSpec spec(layout.width, layout.height, layout.channels, type_desc(options.type));
    if (layout.channel_names.size() == std::size_t(layout.channels)) spec.channelnames = layout.channel_names;
    spec.alpha_channel = layout.alpha_channel;
    spec.attribute("oiio:UnassociatedAlpha", 1);  // write colour as given, never divided by alpha
    // OIIO stamps the current time (EXR capDate, TIFF DateTime) unless told a value; an empty one
    // keeps output bytes a function of the inputs alone.
    spec.attribute("DateTime", "");
    if (!options.colorspace.empty()) spec.attribute("oiio:ColorSpace", options.colorspace);
    std::string compression = options.compression;
    if (compression.empty() && std::string_view(writer->out_->format_name()) == "openexr") compression = "zip";
    if (!compression.empty()) spec.attribute("compression", compression);
    if (!writer->out_->open(written.string(), spec)) {
      return Error{path.string(), "cannot write: " + first_line(writer->out_->geterror())};
    }
    return std::unique_ptr<StoredWriter>(std::move(writer));
  }

  // f32 samples of a half file are rounded to half by OIIO, nearest even.
  Status write(int y, int rows, SampleType type, const void* samples) override {
    if (!out_->write_scanlines(y, y + rows, 0, type_desc(type), samples)) {
      return Error{path_.string(), "cannot write: " + first_line(out_->geterror())};
    }
    return success();
  }

  Status close() override {
    if (!out_->close()) return Error{path_.string(), "cannot write: " + first_line(out_->geterror())};
    return success();
  }

 private:
  explicit OiioWriter(fs::path path) : path_(std::move(path)) {}

  fs::path path_;
  std::unique_ptr<OIIO::Filesystem::IOProxy> proxy_;  // declared before out_: outlives it
  std::unique_ptr<OIIO::ImageOutput> out_;
};

Image resize(const Image& image, int width, int height) {
  const ImageSpec source_spec(image.width, image.height, image.channels, TypeDesc::FLOAT);
  // OIIO wraps the caller's buffer read-only here; it never writes through the pointer.
  const OIIO::ImageBuf source(source_spec, const_cast<float*>(image.pixels.data()));
  OIIO::ImageBuf resized(ImageSpec(width, height, image.channels, TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::resize(resized, source);
  Image out;
  static_cast<ImageLayout&>(out) = image;
  out.width = width;
  out.height = height;
  reserve_pixels(out.pixels, out.sample_count());
  out.pixels.resize(out.sample_count());
  resized.get_pixels(OIIO::ROI::All(), TypeDesc::FLOAT, out.pixels.data());
  return out;
}

void set_thread_count(int threads) { OIIO::attribute("threads", threads); }

const OiioCodecs kCodecs{OiioReader::open, OiioWriter::open, resize, set_thread_count};

}  // namespace
}  // namespace matbake::image

extern "C" const matbake::image::OiioCodecs* matbake_oiio_codecs() { return &matbake::image::kCodecs; }
