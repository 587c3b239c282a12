#pragma once
// `matbake convert`: re-encode images between transfer functions or OCIO colour spaces.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "matbake/color.hpp"
#include "matbake/image.hpp"
#include "matbake/ocio.hpp"
#include "matbake/result.hpp"

namespace matbake::convert {

// Its parameters (all but ocio_config, which is global) are options_params() (convert_params.hpp).
struct Options {
  std::string from = "srgb";    // srgb | gamma2.2 | linear | an OCIO colour space
  std::string to = "linear";    // the same choices
  std::optional<image::SampleType> bits;  // default: see default_sample_type()
  std::string format;                     // of outputs named by output_path_in_folder; empty: by the target
  std::string compression;                // EXR/TIFF, OIIO's name; EXR default: zip
  std::filesystem::path ocio_config;      // empty: $OCIO, else the shipped config
  image::Encoding encoding;  // of PNG outputs
};


// How a conversion runs: either exact built-in transfers at read and write, or (when either side
// names an OCIO colour space) raw I/O around an OCIO processor. Built once for a batch.
struct Plan {
  color::Transfer decode = color::Transfer::linear;
  color::Transfer encode = color::Transfer::linear;
  std::optional<color::OcioProcessor> ocio;
  bool target_is_linear = true;
  std::string ocio_source;  // the OCIO config used, when one is
};

Result<Plan> plan_conversion(const Options& options);

struct Report {
  std::filesystem::path input;
  std::filesystem::path output;
  int width = 0;
  int height = 0;
  int channels = 0;
  image::SampleType input_type = image::SampleType::u8;
  image::SampleType output_type = image::SampleType::u8;
};

// Output extensions matbake writes: exr, png, tif/tiff.
bool is_supported_output_extension(const std::filesystem::path& path);

// EXR: half. PNG/TIFF: 16-bit for a linear target, otherwise the input's depth (16 for float).
image::SampleType default_sample_type(const std::filesystem::path& output, bool target_is_linear,
                                      image::SampleType input_type);

// DIR/<input stem>.<format>; format empty: exr for a linear target, else png.
std::filesystem::path output_path_in_folder(const std::filesystem::path& input,
                                            const std::filesystem::path& folder,
                                            const std::string& format, bool target_is_linear);

Result<Report> convert_file(const Plan& plan, const std::filesystem::path& input,
                                   const std::filesystem::path& output, const Options& options);

}  // namespace matbake::convert
