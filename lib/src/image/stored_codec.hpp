// A codec's side of an image file: samples as the file stores them, in bands of rows. io.cpp
// decodes and encodes them (transfers, non-finite checks); the codecs are ours (png_decode.cpp,
// png_encode.cpp, exr_encode.cpp) or OpenImageIO's, behind the module in oiio_module.hpp.
#pragma once

#include <optional>
#include <string>

#include "matbake/image.hpp"

namespace matbake::image {

// What a file holds: its layout and the closest of our sample types to its own.
struct StoredFormat {
  ImageLayout layout;
  SampleType stored = SampleType::u8;
  std::string format_name;  // OIIO's names: "png", "openexr", "jpeg", ...
  std::optional<color::Transfer> tagged;  // the colour encoding the file itself declares, if any
  std::string tag;                        // that declaration as the file has it ("sRGB chunk")
};

class StoredReader {
 public:
  virtual ~StoredReader() = default;
  const StoredFormat& format() const { return format_; }
  // Rows [y, y + rows) as format().stored samples, channels interleaved, into `samples`. Bands are
  // asked for in order, top to bottom.
  virtual Status read(int y, int rows, void* samples) = 0;

 protected:
  StoredFormat format_;
};

class StoredWriter {
 public:
  virtual ~StoredWriter() = default;
  // Rows [y, y + rows) of u8, u16 or f32 samples (f32 for half and float files), in order.
  virtual Status write(int y, int rows, SampleType type, const void* samples) = 0;
  // The file complete (not yet renamed: the caller's AtomicFile does that).
  virtual Status close() = 0;
};

// OIIO's default channel names for 1 to 4 channels: Y; R G; R G B; R G B A.
std::vector<std::string> default_channel_names(int channels);

}  // namespace matbake::image
