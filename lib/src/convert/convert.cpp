#include "matbake/convert.hpp"
#include "matbake/output_check.hpp"

#include <algorithm>
#include <cctype>

namespace fs = std::filesystem;

namespace matbake::convert {
namespace {

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

bool is_exr(const fs::path& path) { return lower_extension(path) == ".exr"; }

// The tag OIIO writes into the file (PNG sRGB/gAMA chunks, an EXR/TIFF attribute).
std::string colorspace_tag(const Plan& plan, const Options& options) {
  if (plan.ocio) return options.to;
  switch (plan.encode) {
    case color::Transfer::linear: return "Linear";
    case color::Transfer::srgb: return "sRGB";
    case color::Transfer::gamma22: return "Gamma2.2";
  }
  return {};
}

}  // namespace

Result<Plan> plan_conversion(const Options& options) {
  const auto from = color::transfer_from_name(options.from);
  const auto to = color::transfer_from_name(options.to);
  Plan plan;
  if (from && to) {
    plan.decode = *from;
    plan.encode = *to;
    plan.target_is_linear = *to == color::Transfer::linear;
    return plan;
  }
  if (from || to) {
    // A built-in name says nothing of primaries, so it cannot be matched to an OCIO colour space.
    return Error{"",
                 "from and to mix a built-in transfer with an OCIO colour space; name both from the OCIO "
                 "config (e.g. 'sRGB - Texture' and 'Linear Rec.709 (sRGB)') or neither",
                 true};
  }
  auto config = color::OcioConfig::load(options.ocio_config);
  if (!config) return config.error();
  auto processor = config->processor(options.from, options.to);
  if (!processor) return Error{processor.error().path, processor.error().message, true};
  plan.ocio = processor.value();
  plan.target_is_linear = config->is_scene_linear(options.to);
  plan.ocio_source = config->source();
  return plan;
}

bool is_supported_output_extension(const fs::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".exr" || ext == ".png" || ext == ".tif" || ext == ".tiff";
}

image::SampleType default_sample_type(const fs::path& output, bool target_is_linear, image::SampleType input_type) {
  if (is_exr(output)) return image::SampleType::half;
  if (target_is_linear || !image::is_integer(input_type)) return image::SampleType::u16;
  return input_type;
}

fs::path output_path_in_folder(const fs::path& input, const fs::path& folder, const std::string& format,
                               bool target_is_linear) {
  const std::string ext = format.empty() ? (target_is_linear ? "exr" : "png") : format;
  return folder / (input.stem().string() + "." + ext);
}

Result<Report> convert_file(const Plan& plan, const fs::path& input, const fs::path& output,
                                   const Options& options) {
  return guarded(input.string(), [&]() -> Result<Report> {
    if (!is_supported_output_extension(output)) {
      return Error{output.string(), "unsupported output format (matbake writes .exr, .png, .tif)", true};
    }
    if (auto problem = options.bits ? image::sample_type_problem(output, *options.bits) : std::nullopt) {
      return Error{output.string(), *problem, true};
    }
    const NamedOutput outputs[] = {{output, "output"}};
    if (Status s = check_outputs(outputs, std::span(&input, 1)); !s) return s.error();

    // Without --bits the output type depends on the input's, known only once the input is open.
    image::ReadInfo info;
    image::ImageLayout layout;
    image::WriteOptions write{plan.encode, options.bits.value_or(image::SampleType::half), options.compression,
                              colorspace_tag(plan, options), options.encoding.png_level};
    image::BandTransform transform;
    transform.accept = [&](const image::ImageLayout& l) -> Status {
      if (plan.ocio && l.channels < 3) {
        return Error{input.string(), "OCIO colour spaces need RGB or RGBA; this image has " +
                                         std::to_string(l.channels) + " channel(s)"};
      }
      return success();
    };
    if (plan.ocio) {
      transform.apply = [&](std::span<float> band, const image::ImageLayout& l) { plan.ocio->apply(band, l.channels); };
    }
    if (!options.bits) {
      // Peek at the stored type first (opening is cheap: the header only).
      auto probe = image::probe_image(input);
      if (!probe) return probe.error();
      write.type = default_sample_type(output, plan.target_is_linear, probe->stored_type);
    }
    if (Status s = image::stream_image(input, plan.decode, output, write, transform, &info, &layout); !s) {
      return s.error();
    }
    return Report{input, output, layout.width, layout.height, layout.channels, info.stored_type, write.type};
  });
}

}  // namespace matbake::convert
