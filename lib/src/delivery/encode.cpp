#include "encode.hpp"

#include <tbb/task_group.h>
#include <unistd.h>

#include <fstream>

#include "matbake/atomic_file.hpp"
#include "matbake/read_file.hpp"
#include "matbake/ktx2.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

// The level as 8-bit RGB or RGBA, grey spread to RGB, colour channels encoded as the class stores
// them (sRGB for colour), alpha linear; deflate level 0 (stored): read once, then removed.
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
  options.png_level = 0;
  return image::encode_image(rgb, "level.png", options);
}

// The encoder's output, its size checked before it is read: at most `limit` bytes.
Result<std::vector<unsigned char>> read_output(const fs::path& path, std::uintmax_t limit, const std::string& what) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || !fs::is_regular_file(fs::symlink_status(path, ec))) return Error{what, "the encoder wrote no file"};
  if (size > limit) {
    return Error{what, "the encoder wrote " + std::to_string(size) + " bytes, more than the " + std::to_string(limit) +
                           " its levels can take; not read"};
  }
  std::vector<unsigned char> bytes;
  if (!read_whole_file(path, bytes) || bytes.size() > limit) return Error{what, "the encoder's output cannot be read"};
  return bytes;
}

std::uint64_t texels_of(const image::Image& level) { return std::uint64_t(level.width) * std::uint64_t(level.height); }

// Files basisu names itself (after its inputs), removed when the run's scratch files go.
struct EncoderOutputs {
  std::vector<fs::path> paths;
  ~EncoderOutputs() {
    for (const fs::path& p : paths) ::unlink(p.c_str());
  }
};

// One basisu run over `levels`: each written as a scratch PNG, each encoded into a KTX2 file beside
// it; their bytes, in order.
Result<std::vector<std::vector<unsigned char>>> run_on(const Encoder& encoder, const std::vector<const image::Image*>& levels,
                                                       const EncodeRequest& request, std::vector<std::string> args) {
  std::vector<AtomicFile> inputs;
  std::uint64_t texels = 0;
  for (const image::Image* level : levels) {
    texels += texels_of(*level);
    auto png = png_bytes(*level, request);
    if (!png) return png.error();
    auto input = AtomicFile::create(fs::path(request.scratch).replace_extension(".basisu-in.png"));
    if (!input) return input.error();
    std::ofstream out(input->temp_path(), std::ios::binary);
    out.write(png->data(), std::streamsize(png->size()));
    if (!out) return Error{input->temp_path().string(), "cannot write the encoder's input"};
    inputs.push_back(std::move(*input));
  }
  EncoderOutputs outputs;  // declared after the inputs: removed first, so their folder can go with them
  args.insert(args.end(), {"-max_threads", std::to_string(request.threads), "-output_path", inputs[0].temp_path().parent_path().string()});
  for (const AtomicFile& input : inputs) {
    args.push_back(input.temp_path().string());
    outputs.paths.push_back(fs::path(input.temp_path()).replace_extension(".ktx2"));
  }
  const std::string what = request.scratch.string();
  if (Status s = run_encoder(encoder, args, what, texels); !s) return s.error();
  std::vector<std::vector<unsigned char>> files;
  for (std::size_t i = 0; i < outputs.paths.size(); ++i) {
    // UASTC is a byte a texel; ETC1S less; a whole mip chain under 4/3 of that; plus the header.
    auto bytes = read_output(outputs.paths[i], 2 * texels_of(*levels[i]) + (1u << 20), what);
    if (!bytes) return bytes.error();
    files.push_back(std::move(*bytes));
  }
  return files;
}

// The UASTC blocks of each file basisu wrote for one level.
Result<std::vector<unsigned char>> blocks_of(const Encoder& encoder, const std::vector<unsigned char>& file, const image::Image& level,
                                             const std::string& name) {
  auto texture = ktx2::read(file, name + " (basisu's output)");
  if (!texture) return texture.error();
  if (texture->descriptor.model != ktx2::kModelUASTC || texture->supercompression != ktx2::kSupercompressionNone ||
      texture->width != unsigned(level.width) || texture->height != unsigned(level.height)) {
    return Error{name, "basisu " + encoder.version + " wrote an unexpected KTX2 file (not plain UASTC of the level's size)"};
  }
  return ktx2::level_data(*texture, 0, name);
}

// UASTC: level 0 encoded while the other levels are made, then the other levels in one run while
// level 0 is supercompressed.
Result<std::vector<ktx2::Level>> uastc_levels(const Encoder& encoder, const image::Image& level0, tbb::task_group& work,
                                              const std::vector<image::Image>& rest, const EncodeRequest& request) {
  const std::vector<std::string> args = encoder_arguments(request);
  std::vector<Result<ktx2::Level>> stored;
  auto first = run_on(encoder, {&level0}, request, args);
  work.wait();  // the other levels
  if (!first) return first.error();
  std::vector<const image::Image*> others;
  for (const image::Image& l : rest) others.push_back(&l);
  std::vector<std::vector<unsigned char>> blocks(1 + rest.size());
  stored.assign(blocks.size(), Error{"", "not encoded"});
  const std::string name = request.scratch.string();
  auto supercompress = [&](std::size_t l, const image::Image& level, const std::vector<unsigned char>& file) {
    auto b = blocks_of(encoder, file, level, name);
    if (!b) {
      stored[l] = b.error();
      return;
    }
    blocks[l] = std::move(*b);
    work.run([&stored, &blocks, l, zstd = request.options.zstd] { stored[l] = ktx2::uastc_level(std::move(blocks[l]), zstd); });
  };
  supercompress(0, level0, (*first)[0]);
  auto later = others.empty() ? Result<std::vector<std::vector<unsigned char>>>(std::vector<std::vector<unsigned char>>{})
                              : run_on(encoder, others, request, args);
  if (later) {
    for (std::size_t i = 0; i < rest.size(); ++i) supercompress(i + 1, rest[i], (*later)[i]);
  }
  work.wait();
  if (!later) return later.error();
  std::vector<ktx2::Level> levels;
  for (Result<ktx2::Level>& l : stored) {
    if (!l) return l.error();
    levels.push_back(std::move(*l));
  }
  return levels;
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
    // basisu's chain (each level from the one before: -mip_slow's levels from the base cost 50% more
    // time for no measured gain, docs/delivery.md), in linear light for colour, renormalised normals.
    args.insert(args.end(), {"-mipmap", "-mip_filter", request.sampling.filter == Filter::box ? "box" : "kaiser",
                             request.texture_class == TextureClass::colour ? "-mip_srgb" : "-mip_linear"});
    if (request.texture_class == TextureClass::normal) args.push_back("-mip_renorm");
    if (request.sampling.wrap_s == Wrap::clamp_to_edge || request.sampling.wrap_t == Wrap::clamp_to_edge) args.push_back("-mip_clamp");
  }
  return args;
}

Result<Encoded> encode_texture(const Encoder& encoder, const image::Image& source, Size base, const MipRequest& mips,
                               const EncodeRequest& request, const std::string& writer) {
  const bool uastc = request.options.codec == Codec::uastc;
  std::vector<Size> sizes = uastc && request.mipmaps ? mip_sizes(base) : std::vector<Size>{base};
  const image::Image level0 = std::move(mip_levels(source, {base}, mips)[0]);
  std::vector<image::Image> rest;
  tbb::task_group work;
  if (sizes.size() > 1) work.run([&] { rest = mip_levels(source, {sizes.begin() + 1, sizes.end()}, mips); });
  Encoded out;
  if (!uastc) {
    auto file = run_on(encoder, {&level0}, request, encoder_arguments(request));
    work.wait();
    if (!file) return file.error();
    out.file = std::move((*file)[0]);
    auto read = ktx2::read(out.file, request.scratch.string());  // basisu's own chain
    if (!read) return read.error();
    const std::size_t expected = request.mipmaps ? mip_sizes(base).size() : 1;
    if (read->descriptor.model != ktx2::kModelETC1S || read->width != unsigned(base.width) || read->height != unsigned(base.height) ||
        read->levels.size() != expected) {
      return Error{request.scratch.string(), "basisu " + encoder.version + " wrote an unexpected KTX2 file (" +
                                                 std::to_string(read->width) + "x" + std::to_string(read->height) + ", " +
                                                 std::to_string(read->levels.size()) + " levels; asked for ETC1S " +
                                                 std::to_string(base.width) + "x" + std::to_string(base.height) + ", " +
                                                 std::to_string(expected) + " levels)"};
    }
    out.levels = int(read->levels.size());
    if (auto conformed = ktx2::conform_primaries(out.file, request.scratch.string()); !conformed) return conformed.error();
  } else {
    auto levels = uastc_levels(encoder, level0, work, rest, request);
    if (!levels) return levels.error();
    ktx2::UastcFile file{.width = unsigned(base.width), .height = unsigned(base.height),
                         .transfer = request.texture_class == TextureClass::colour ? ktx2::kTransferSRGB : ktx2::kTransferLinear,
                         .channel = request.alpha ? ktx2::kUastcRGBA : ktx2::kUastcRGB, .levels = std::move(*levels),
                         .zstd = request.options.zstd > 0, .writer = writer};
    auto bytes = ktx2::write_uastc(file);
    if (!bytes) return bytes.error();
    out.file = std::move(*bytes);
    out.levels = int(sizes.size());
  }
  if (mips.alpha_cutoff) {
    out.coverage = {alpha_coverage(source, *mips.alpha_cutoff), alpha_coverage(level0, *mips.alpha_cutoff)};
    for (const image::Image& l : rest) out.coverage.push_back(alpha_coverage(l, *mips.alpha_cutoff));
  }
  return out;
}

}  // namespace matbake::delivery
