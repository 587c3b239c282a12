#include "encode.hpp"

#include <fstream>
#include <iterator>

#include "matbake/atomic_file.hpp"
#include "matbake/ktx2.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

// The level as 8-bit RGB or RGBA, grey spread to RGB, colour channels encoded as the class stores
// them (sRGB for colour), alpha linear.
Result<std::string> png_bytes(const image::Image& level, const EncodeRequest& request) {
  image::Image rgb;
  static_cast<image::ImageLayout&>(rgb) = level;
  rgb.channels = request.alpha ? 4 : 3;
  rgb.channel_names = request.alpha ? std::vector<std::string>{"R", "G", "B", "A"} : std::vector<std::string>{"R", "G", "B"};
  rgb.alpha_channel = request.alpha ? 3 : -1;
  const std::size_t pixels = std::size_t(level.width) * std::size_t(level.height), ch = std::size_t(level.channels);
  rgb.pixels.resize(pixels * std::size_t(rgb.channels));
  for (std::size_t p = 0; p < pixels; ++p) {
    const float* in = &level.pixels[p * ch];
    float* out = &rgb.pixels[p * std::size_t(rgb.channels)];
    for (int c = 0; c < 3; ++c) out[c] = ch >= 3 ? in[c] : in[0];
    if (request.alpha) out[3] = level.alpha_channel >= 0 ? in[level.alpha_channel] : 1.0f;
  }
  image::WriteOptions options;
  options.type = image::SampleType::u8;
  options.colour = request.texture_class == TextureClass::colour ? color::Transfer::srgb : color::Transfer::linear;
  options.png_level = 1;  // read once by the encoder, then removed
  return image::encode_image(rgb, "level.png", options);
}

Result<std::vector<unsigned char>> read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) return Error{path.string(), "cannot read the encoder's output"};
  return bytes;
}

// Writes the level as a scratch PNG, runs basisu on it into a scratch KTX2 and returns that file.
Result<std::vector<unsigned char>> run_on(const Encoder& encoder, const image::Image& level, const EncodeRequest& request,
                                          std::vector<std::string> args) {
  auto png = png_bytes(level, request);
  if (!png) return png.error();
  const fs::path stem = request.scratch;
  auto input = AtomicFile::create(fs::path(stem).replace_extension(".basisu-in.png"));
  auto output = AtomicFile::create(fs::path(stem).replace_extension(".basisu-out.ktx2"));
  auto log = AtomicFile::create(fs::path(stem).replace_extension(".basisu.log"));
  for (const auto* made : {&input, &output, &log}) {
    if (!*made) return made->error();
  }
  {
    std::ofstream out(input->temp_path(), std::ios::binary);
    out.write(png->data(), std::streamsize(png->size()));
    if (!out) return Error{input->temp_path().string(), "cannot write the encoder's input"};
  }
  args.insert(args.end(), {"-output_file", output->temp_path().string(), input->temp_path().string()});
  if (Status s = run_encoder(encoder, args, log->temp_path(), request.scratch.string()); !s) return s.error();
  return read_all(output->temp_path());
}

}  // namespace

bool has_alpha(const image::Image& im) {
  if (im.alpha_channel < 0) return false;
  const std::size_t pixels = std::size_t(im.width) * std::size_t(im.height), ch = std::size_t(im.channels);
  for (std::size_t p = 0; p < pixels; ++p) {
    if (im.pixels[p * ch + std::size_t(im.alpha_channel)] < 254.5f / 255.0f) return true;
  }
  return false;
}

std::vector<std::string> encoder_arguments(const EncodeRequest& request) {
  const ClassOptions& o = request.options;
  std::vector<std::string> args{"-ktx2", request.alpha ? "-force_alpha" : "-no_alpha"};
  if (request.texture_class == TextureClass::normal) args.push_back("-normal_map");
  else if (request.texture_class == TextureClass::data) args.push_back("-linear");
  if (o.codec == Codec::uastc) {
    args.insert(args.end(), {"-uastc", "-uastc_level", std::to_string(o.uastc_level), "-ktx2_no_zstandard"});
    // Single-threaded RDO: basisu's threaded RDO depends on the thread count; this does not.
    if (o.uastc_rdo > 0) args.insert(args.end(), {"-uastc_rdo_l", std::to_string(o.uastc_rdo), "-uastc_rdo_m"});
    return args;
  }
  args.insert(args.end(), {"-q", std::to_string(o.quality)});
  if (request.mipmaps) {
    // From the base at every level, in linear light for colour, renormalised normals.
    args.insert(args.end(), {"-mipmap", "-mip_slow", "-mip_filter", request.sampling.filter == Filter::box ? "box" : "kaiser",
                             request.texture_class == TextureClass::colour ? "-mip_srgb" : "-mip_linear"});
    if (request.texture_class == TextureClass::normal) args.push_back("-mip_renorm");
    if (request.sampling.wrap_s == Wrap::clamp || request.sampling.wrap_t == Wrap::clamp) args.push_back("-mip_clamp");
  }
  return args;
}

Result<std::vector<unsigned char>> encode_uastc_level(const Encoder& encoder, const image::Image& level, const EncodeRequest& request) {
  std::vector<std::string> args = encoder_arguments(request);
  args.insert(args.end(), {"-max_threads", std::to_string(request.threads)});
  auto file = run_on(encoder, level, request, args);
  if (!file) return file.error();
  auto texture = ktx2::read(*file, request.scratch.string() + " (basisu's output)");
  if (!texture) return texture.error();
  if (texture->descriptor.model != ktx2::kModelUASTC || texture->supercompression != ktx2::kSupercompressionNone ||
      texture->width != unsigned(level.width) || texture->height != unsigned(level.height)) {
    return Error{request.scratch.string(), "basisu " + encoder.version + " wrote an unexpected KTX2 file (not plain UASTC of the level's size)"};
  }
  return ktx2::level_data(*texture, 0, request.scratch.string());
}

Result<std::vector<unsigned char>> encode_etc1s(const Encoder& encoder, const image::Image& base, const EncodeRequest& request) {
  std::vector<std::string> args = encoder_arguments(request);
  args.insert(args.end(), {"-max_threads", std::to_string(request.threads)});
  return run_on(encoder, base, request, args);
}

}  // namespace matbake::delivery
