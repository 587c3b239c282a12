#include "encode.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>
#include <unistd.h>

#include <deque>
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

// UASTC blocks per basisu run when a level is split (1024 × 1024 texels). Each run's RDO starts afresh:
// on WaterBottle's 2048² colour texture (λ 1, zstd 18) 4 strips cost 2.0% more bytes than one run,
// 16 strips 4.0% (docs/delivery.md).
constexpr int kStripBlocks = 65536;

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

// One basisu run of UASTC: the pieces it encodes, each a whole level or a strip of one.
struct Piece {
  std::size_t level = 0;  // its index in the chain
  const image::Image* image = nullptr;
  int first_row = 0, rows = 0;  // texel rows of the level
};

// Rows `first` to `first + rows` of `level`.
image::Image rows_of(const image::Image& level, int first, int rows) {
  image::Image strip;
  static_cast<image::ImageLayout&>(strip) = level;
  strip.height = rows;
  const std::size_t row = std::size_t(level.width) * std::size_t(level.channels);
  strip.pixels.assign(level.pixels.begin() + std::ptrdiff_t(row * std::size_t(first)),
                      level.pixels.begin() + std::ptrdiff_t(row * std::size_t(first + rows)));
  return strip;
}

// The basisu runs of a chain's UASTC levels from `first_level` on: a level larger than a strip
// (kStripBlocks) in strips of whole block rows, each its own run; the smaller ones in one run.
std::vector<std::vector<Piece>> plan_runs(const std::vector<const image::Image*>& levels, std::size_t first_level) {
  std::vector<std::vector<Piece>> runs;
  std::vector<Piece> small;
  for (std::size_t l = first_level; l < levels.size(); ++l) {
    const image::Image& level = *levels[l];
    const int strip_rows = 4 * std::max(1, kStripBlocks / ((level.width + 3) / 4));
    if (level.height <= strip_rows) {
      small.push_back({l, &level, 0, level.height});
      continue;
    }
    for (int y = 0; y < level.height; y += strip_rows) runs.push_back({{l, &level, y, std::min(strip_rows, level.height - y)}});
  }
  if (!small.empty()) runs.push_back(std::move(small));
  return runs;
}

// One run: each piece's blocks (row-major, as the level stores them).
Result<std::vector<std::vector<unsigned char>>> encode_run(const Encoder& encoder, const std::vector<Piece>& run,
                                                           const EncodeRequest& request, const std::vector<std::string>& args) {
  std::vector<image::Image> strips;
  std::vector<const image::Image*> inputs;
  strips.reserve(run.size());
  for (const Piece& piece : run) {
    const image::Image& level = *piece.image;
    const bool whole = piece.rows == level.height;
    if (!whole) strips.push_back(rows_of(level, piece.first_row, piece.rows));
    inputs.push_back(whole ? &level : &strips.back());
  }
  auto files = run_on(encoder, inputs, request, args);
  if (!files) return files.error();
  std::vector<std::vector<unsigned char>> blocks;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    auto b = blocks_of(encoder, (*files)[i], *inputs[i], request.scratch.string());
    if (!b) return b.error();
    blocks.push_back(std::move(*b));
  }
  return blocks;
}

// UASTC, every level's runs in parallel (level 0's while the other levels are made), one encoder
// thread each: RDO works through a run's blocks in order, so its bytes depend on where runs split,
// and the split depends on the level's size alone, never on the thread count; then each level
// supercompressed.
Result<std::vector<ktx2::Level>> uastc_levels(const Encoder& encoder, const image::Image& level0, tbb::task_group& work,
                                              const std::vector<image::Image>& rest, const EncodeRequest& request) {
  EncodeRequest one_thread = request;
  one_thread.threads = 1;
  const std::vector<std::string> args = encoder_arguments(request);
  std::vector<const image::Image*> levels{&level0};
  // Deques: a run started keeps its place while later ones are added.
  std::deque<std::vector<Piece>> runs;
  std::deque<Result<std::vector<std::vector<unsigned char>>>> encoded;
  tbb::task_group encoding;
  auto start = [&](std::vector<std::vector<Piece>> planned) {
    for (std::vector<Piece>& run : planned) {
      const std::vector<Piece>& pieces = runs.emplace_back(std::move(run));
      auto& result = encoded.emplace_back(Error{"", "not encoded"});
      encoding.run([&encoder, &one_thread, &args, p = &pieces, out = &result] { *out = encode_run(encoder, *p, one_thread, args); });
    }
  };
  start(plan_runs(levels, 0));
  work.wait();  // the other levels
  for (const image::Image& l : rest) levels.push_back(&l);
  start(plan_runs(levels, 1));
  encoding.wait();
  std::vector<std::vector<unsigned char>> blocks(levels.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {  // in order: a level's strips join top to bottom
    if (!encoded[r]) return encoded[r].error();
    for (std::size_t i = 0; i < runs[r].size(); ++i) {
      std::vector<unsigned char>& level = blocks[runs[r][i].level];
      level.insert(level.end(), (*encoded[r])[i].begin(), (*encoded[r])[i].end());
    }
  }
  std::vector<Result<ktx2::Level>> stored(blocks.size(), Error{"", "not stored"});
  tbb::parallel_for(std::size_t(0), blocks.size(), [&](std::size_t l) { stored[l] = ktx2::uastc_level(std::move(blocks[l]), request.options.zstd); });
  std::vector<ktx2::Level> out;
  for (Result<ktx2::Level>& l : stored) {
    if (!l) return l.error();
    out.push_back(std::move(*l));
  }
  return out;
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
    // basisu's own threaded RDO splits a level by its thread count (and the machine's): matbake splits
    // it by size (uastc_levels) and runs each piece single-threaded.
    if (o.uastc_rdo > 0) {
      args.insert(args.end(), {"-uastc_rdo_l", std::to_string(o.uastc_rdo), "-uastc_rdo_d", std::to_string(o.uastc_rdo_dictionary), "-uastc_rdo_m"});
    }
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
