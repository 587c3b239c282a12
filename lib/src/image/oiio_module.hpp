// OpenImageIO's codecs, in a module of matbake's own (libmatbake_oiio.so, lib/src/image/oiio/)
// that libmatbake loads the first time a file needs them: PNG, and EXR written as half or float
// with none/zip/zips, never load it. OIIO brings about 260 shared libraries (OpenCV, FFmpeg, GDAL,
// DCMTK, ...) that cost 0.4 s of every process's start (docs/performance.md); a run that reads
// PNG and writes PNG or EXR no longer pays it.
#pragma once

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "stored_codec.hpp"

namespace matbake::image {

// What the module provides. Same compiler and library as libmatbake: C++ types cross freely.
struct OiioCodecs {
  // Any image OIIO reads, by content; `memory` (when not empty) holds its bytes and must outlive
  // the reader, and `name`'s extension is OIIO's first guess. Alpha stays unassociated.
  Result<std::unique_ptr<StoredReader>> (*open_reader)(const std::filesystem::path& name,
                                                       std::span<const unsigned char> memory);
  // The format of `written`'s extension, into `written` or, when `memory` is set, into it;
  // `path` names the file in errors.
  Result<std::unique_ptr<StoredWriter>> (*open_writer)(const std::filesystem::path& path,
                                                       const std::filesystem::path& written,
                                                       std::vector<unsigned char>* memory, const ImageLayout& layout,
                                                       const WriteOptions& options);
  Image (*resize)(const Image& image, int width, int height);  // see resize_image
  void (*set_thread_count)(int threads);
};

// The module, loaded from beside libmatbake on the first call (thread-safe). `user` names what
// needed it in the error when it cannot be loaded.
Result<const OiioCodecs*> oiio_codecs(const std::string& user);

}  // namespace matbake::image

// The module's one export.
extern "C" const matbake::image::OiioCodecs* matbake_oiio_codecs();
