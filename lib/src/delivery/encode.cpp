#include "encode.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>
#include <unistd.h>

#include <atomic>
#include <deque>
#include <limits>
#include <mutex>
#include <fstream>

#include "level_error.hpp"
#include "matbake/atomic_file.hpp"
#include "matbake/read_file.hpp"
#include "matbake/ktx2.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

// Rows [first, first + rows) of `level` as 8-bit RGB or RGBA PNG, each texel as texel_as_stored makes
// it (renormalise: what mip_levels does at the source's own size); deflate level 0 (stored): read
// once, then removed. Written band by band, never copied whole.
Result<std::string> png_bytes(const image::Image& level, int first, int rows, const EncodeRequest& request, bool renormalise) {
  image::ImageLayout rgb = level;
  rgb.height = rows;
  rgb.channels = request.alpha ? 4 : 3;
  rgb.channel_names = request.alpha ? std::vector<std::string>{"R", "G", "B", "A"} : std::vector<std::string>{"R", "G", "B"};
  rgb.alpha_channel = request.alpha ? 3 : -1;
  const std::size_t out_ch = std::size_t(rgb.channels), first_texel = std::size_t(first) * std::size_t(level.width);
  const auto fill = [&](int y, int band_rows, std::span<float> samples) {
    const std::size_t texels = std::size_t(level.width) * std::size_t(band_rows), band = std::size_t(y) * std::size_t(level.width);
    for (std::size_t p = 0; p < texels; ++p) texel_as_stored(level, first_texel + band + p, request, renormalise, &samples[p * out_ch]);
  };
  image::WriteOptions options;
  options.type = image::SampleType::u8;
  options.colour = stored_transfer(request);
  options.png_level = 0;
  return image::encode_bands(rgb, fill, "level.png", options);
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

// UASTC blocks per basisu run (1024 × 1024 texels): a larger level is split into strips of whole
// block rows. Each run's RDO starts afresh: on WaterBottle's 2048² colour texture (λ 1, zstd 18) 4
// strips cost 2.0% more bytes than one run, 16 strips 4.0% (docs/delivery.md).
constexpr std::uint64_t kStripBlocks = 65536;

std::uint64_t blocks_of(Size s) { return std::uint64_t((s.width + 3) / 4) * std::uint64_t((s.height + 3) / 4); }

// What basisu encodes in one file: a whole level or a strip of one, as the 8-bit PNG it reads.
struct Piece {
  std::size_t level = 0;  // its index in the chain
  Size size;
  std::string png;
};

// Files basisu names itself (after its inputs), removed when the run's scratch files go.
struct EncoderOutputs {
  std::vector<fs::path> paths;
  ~EncoderOutputs() {
    for (const fs::path& p : paths) remove_program_output(p);
  }
};

// One basisu run over `pieces`: each written as a scratch PNG, each encoded into a KTX2 file beside
// it (basisu encodes every input file on its own, so a piece's bytes do not depend on its run);
// their bytes, in order.
Result<std::vector<std::vector<unsigned char>>> run_on(const Encoder& encoder, const std::vector<const Piece*>& pieces,
                                                       const EncodeRequest& request, std::vector<std::string> args) {
  std::vector<AtomicFile> inputs;
  std::uint64_t texels = 0;
  for (const Piece* piece : pieces) {
    texels += std::uint64_t(piece->size.width) * std::uint64_t(piece->size.height);
    auto input = AtomicFile::create(fs::path(request.scratch).replace_extension(".basisu-in.png"));
    if (!input) return input.error();
    std::ofstream out(input->temp_path(), std::ios::binary);
    out.write(piece->png.data(), std::streamsize(piece->png.size()));
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
    const Size s = pieces[i]->size;
    auto bytes = read_output(outputs.paths[i], 2 * std::uint64_t(s.width) * std::uint64_t(s.height) + (1u << 20), what);
    if (!bytes) return bytes.error();
    files.push_back(std::move(*bytes));
  }
  return files;
}

// The UASTC blocks of the file basisu wrote for one piece.
Result<std::vector<unsigned char>> uastc_blocks(const Encoder& encoder, const std::vector<unsigned char>& file, Size size,
                                                const std::string& name) {
  auto texture = ktx2::read(file, name + " (basisu's output)");
  if (!texture) return texture.error();
  if (texture->descriptor.model != ktx2::kModelUASTC || texture->supercompression != ktx2::kSupercompressionNone ||
      texture->width != unsigned(size.width) || texture->height != unsigned(size.height)) {
    return Error{name, "basisu " + encoder.version + " wrote an unexpected KTX2 file (not plain UASTC of the level's size)"};
  }
  return ktx2::level_data(*texture, 0, name);
}

// A chain's levels as pieces, in order: a level of more than `max_blocks` blocks in strips of whole
// block rows (where it splits depends on its size alone, never on the thread count), the others whole.
// With `renormalise`, a normal map's texels are made unit length on the way (the source, level 0 at its
// own size, is cut as it is).
Result<std::vector<Piece>> pieces_of(const std::vector<const image::Image*>& levels, const EncodeRequest& request,
                                     std::uint64_t max_blocks, bool renormalise = false) {
  struct Cut {
    std::size_t level;
    int first_row, rows;
  };
  std::vector<Cut> cuts;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const image::Image& level = *levels[l];
    const std::uint64_t rows = std::max<std::uint64_t>(1, max_blocks / std::uint64_t((level.width + 3) / 4));
    const int strip_rows = int(std::min<std::uint64_t>(4 * rows, std::uint64_t(level.height)));
    for (int y = 0; y < level.height; y += strip_rows) cuts.push_back({l, y, std::min(strip_rows, level.height - y)});
  }
  std::vector<Piece> pieces(cuts.size());
  std::vector<Status> made(cuts.size(), success());
  tbb::parallel_for(std::size_t(0), cuts.size(), [&](std::size_t i) {
    const image::Image& level = *levels[cuts[i].level];
    auto png = png_bytes(level, cuts[i].first_row, cuts[i].rows, request, renormalise && level.channels >= 3);
    if (!png) {
      made[i] = png.error();
      return;
    }
    pieces[i] = {cuts[i].level, {level.width, cuts[i].rows}, std::move(*png)};
  });
  for (Status& s : made) {
    if (!s) return s.error();
  }
  return pieces;
}

// Consecutive pieces joined into runs of at most kStripBlocks blocks (a piece alone may fill one):
// a process per small level would cost more than its encode.
std::vector<std::vector<std::size_t>> plan_runs(const std::vector<Piece>& pieces) {
  std::vector<std::vector<std::size_t>> runs;
  std::uint64_t filled = kStripBlocks;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::uint64_t blocks = blocks_of(pieces[i].size);
    if (filled + blocks > kStripBlocks) {
      runs.emplace_back();
      filled = 0;
    }
    runs.back().push_back(i);
    filled += blocks;
  }
  return runs;
}

// A part of a UASTC chain on its way through basisu: its pieces, their runs (largest first), and
// each piece's blocks once encoded.
struct Batch {
  std::vector<Piece> pieces;
  std::vector<std::vector<std::size_t>> runs;
  std::vector<Result<std::vector<unsigned char>>> blocks;
  std::atomic<std::size_t> next{0};  // the run the next task takes
};

// Starts `batch`'s runs in `encoding`, one encoder thread each: RDO works through a piece's blocks
// in order, so its bytes depend on where a level splits, never on the thread count. Each task takes
// the next run in order, so that the largest start first and no long one starts last.
void start_runs(tbb::task_group& encoding, Batch& batch, const Encoder& encoder, const EncodeRequest& request,
                const std::vector<std::string>& args) {
  batch.runs = plan_runs(batch.pieces);
  const auto blocks = [&](const std::vector<std::size_t>& run) {
    std::uint64_t n = 0;
    for (std::size_t i : run) n += blocks_of(batch.pieces[i].size);
    return n;
  };
  std::stable_sort(batch.runs.begin(), batch.runs.end(), [&](const auto& x, const auto& y) { return blocks(x) > blocks(y); });
  batch.blocks.assign(batch.pieces.size(), Error{"", "not encoded"});
  for (std::size_t r = 0; r < batch.runs.size(); ++r) {
    encoding.run([&batch, &encoder, &request, &args] {
      const std::vector<std::size_t>& run = batch.runs[batch.next++];
      std::vector<const Piece*> inputs;
      for (std::size_t i : run) inputs.push_back(&batch.pieces[i]);
      auto files = run_on(encoder, inputs, request, args);
      for (std::size_t k = 0; k < run.size(); ++k) {
        const Piece& piece = batch.pieces[run[k]];
        batch.blocks[run[k]] = files ? uastc_blocks(encoder, (*files)[k], piece.size, request.scratch.string())
                                     : Result<std::vector<unsigned char>>(files.error());
      }
    });
  }
}

// The levels of `batches` (in chain order), each level's blocks joined top to bottom and
// supercompressed.
Result<std::vector<ktx2::Level>> join_levels(std::deque<Batch>& batches, std::size_t level_count, int zstd) {
  std::vector<std::vector<unsigned char>> level_blocks(level_count);
  for (Batch& batch : batches) {
    for (std::size_t i = 0; i < batch.pieces.size(); ++i) {
      if (!batch.blocks[i]) return batch.blocks[i].error();
      std::vector<unsigned char>& level = level_blocks[batch.pieces[i].level];
      level.insert(level.end(), batch.blocks[i]->begin(), batch.blocks[i]->end());
    }
  }
  std::vector<Result<ktx2::Level>> stored(level_count, Error{"", "not stored"});
  tbb::parallel_for(std::size_t(0), level_count, [&](std::size_t l) { stored[l] = ktx2::uastc_level(std::move(level_blocks[l]), zstd); });
  std::vector<ktx2::Level> out;
  for (Result<ktx2::Level>& l : stored) {
    if (!l) return l.error();
    out.push_back(std::move(*l));
  }
  return out;
}

// The chain of `source` as UASTC levels. A level 0 in strips: made and its runs (the largest)
// started first, the other levels made from the source meanwhile, then theirs. Levels are held as
// basisu reads them (8-bit PNG, a quarter of the floats) from when they are made; the source goes
// with the last.
Result<std::vector<ktx2::Level>> uastc_chain(const Encoder& encoder, image::Image source, const std::vector<Size>& sizes,
                                             const MipRequest& mips, const EncodeRequest& request, std::vector<double>& coverage) {
  EncodeRequest one_thread = request;
  one_thread.threads = 1;
  const std::vector<std::string> args = encoder_arguments(request);
  std::deque<Batch> batches;  // a batch keeps its place while its runs read it
  tbb::task_group encoding;
  const auto add_batch = [&](const std::vector<const image::Image*>& chain, std::size_t first_level, bool renormalise) -> Status {
    for (const image::Image* l : chain) {
      if (mips.alpha_cutoff) coverage.push_back(alpha_coverage(*l, *mips.alpha_cutoff));
    }
    auto pieces = pieces_of(chain, request, kStripBlocks, renormalise);
    if (!pieces) return pieces.error();
    for (Piece& p : *pieces) p.level += first_level;
    Batch& batch = batches.emplace_back();
    batch.pieces = std::move(*pieces);
    start_runs(encoding, batch, encoder, one_thread, args);
    return success();
  };
  const auto pointers = [](const std::vector<image::Image>& levels) {
    std::vector<const image::Image*> out;
    for (const image::Image& l : levels) out.push_back(&l);
    return out;
  };
  Status status = success();
  if (blocks_of(sizes[0]) <= kStripBlocks) {
    // Level 0 is one piece: the chain made whole first goes in as few runs as its size allows.
    status = add_batch(pointers(mip_levels(std::move(source), sizes, mips)), 0, false);
  } else {
    if (sizes[0] == Size{source.width, source.height}) {
      // Level 0 cut from the source, not copied: at its own size a level is the source renormalised.
      status = add_batch({&source}, 0, mips.texture_class == TextureClass::normal);
    } else {
      status = add_batch(pointers(mip_levels(source, {sizes[0]}, mips)), 0, false);
    }
    if (status && sizes.size() > 1) {
      // The source goes with this statement.
      status = add_batch(pointers(mip_levels(image::Image(std::move(source)), {sizes.begin() + 1, sizes.end()}, mips)), 1, false);
    }
  }
  encoding.wait();
  if (!status) return status.error();
  return join_levels(batches, sizes.size(), request.options.zstd);
}

}  // namespace

void texel_as_stored(const image::Image& level, std::size_t p, const EncodeRequest& request, bool renormalise, float* out) {
  const std::size_t ch = std::size_t(level.channels);
  const float* in = &level.pixels[p * ch];
  for (std::size_t c = 0; c < 3; ++c) out[c] = ch >= 3 ? in[c] : in[0];
  if (renormalise) renormalise_normal(out);
  if (request.alpha) out[3] = level.alpha_channel >= 0 ? in[level.alpha_channel] : 1.0f;
}

color::Transfer stored_transfer(const EncodeRequest& request) {
  return request.texture_class == TextureClass::colour ? color::Transfer::srgb : color::Transfer::linear;
}

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
    // it by size (pieces_of) and runs each piece single-threaded.
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

namespace {

// encode_texture's file, its levels and their coverage.
Result<Encoded> encoded_chain(const Encoder& encoder, image::Image source, Size base, const MipRequest& mips,
                              const EncodeRequest& request, const std::string& writer) {
  Encoded out;
  if (mips.alpha_cutoff) out.coverage.push_back(alpha_coverage(source, *mips.alpha_cutoff));
  if (request.options.codec == Codec::uastc) {
    const std::vector<Size> sizes = request.mipmaps ? mip_sizes(base) : std::vector<Size>{base};
    auto levels = uastc_chain(encoder, std::move(source), sizes, mips, request, out.coverage);
    if (!levels) return levels.error();
    ktx2::UastcFile file{.width = unsigned(base.width), .height = unsigned(base.height),
                         .transfer = request.texture_class == TextureClass::colour ? ktx2::kTransferSRGB : ktx2::kTransferLinear,
                         .channel = request.alpha ? ktx2::kUastcRGBA : ktx2::kUastcRGB, .levels = std::move(*levels),
                         .zstd = request.options.zstd > 0, .writer = writer};
    auto bytes = ktx2::write_uastc(file);
    if (!bytes) return bytes.error();
    out.file = std::move(*bytes);
    out.levels = int(sizes.size());
    return out;
  }
  // ETC1S: level 0 alone, basisu making the chain.
  std::vector<image::Image> level0 = mip_levels(std::move(source), {base}, mips);
  if (mips.alpha_cutoff) out.coverage.push_back(alpha_coverage(level0[0], *mips.alpha_cutoff));
  auto pieces = pieces_of({&level0[0]}, request, std::numeric_limits<std::uint64_t>::max());
  if (!pieces) return pieces.error();
  level0.clear();
  // A large ETC1S run (a megatexel or more) one at a time, each with the request's threads: basisu
  // threads ETC1S itself (its bytes do not depend on the thread count), and a run holds ~200 MB at
  // 2048², so two at once doubled the peak (docs/delivery.md#against-gltfpack-with-basisu). Small
  // runs, mostly the process's start, go in parallel. A thread waiting here holds no lock of tbb.
  static std::mutex one_large_run;
  std::unique_lock lock(one_large_run, std::defer_lock);
  if (std::uint64_t(base.width) * std::uint64_t(base.height) >= (1u << 20)) lock.lock();
  auto file = run_on(encoder, {&pieces->front()}, request, encoder_arguments(request));
  if (lock.owns_lock()) lock.unlock();
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
  return out;
}

}  // namespace

Result<Encoded> encode_texture(const Encoder& encoder, image::Image source, Size base, const MipRequest& mips,
                               const EncodeRequest& request, const std::string& writer) {
  if (!request.measure_levels) return encoded_chain(encoder, std::move(source), base, mips, request, writer);
  const image::Image reference = source;  // what the delivered levels are measured against
  auto out = encoded_chain(encoder, std::move(source), base, mips, request, writer);
  if (!out) return out;
  const std::vector<Size> sizes = out->levels > 1 ? mip_sizes(base) : std::vector<Size>{base};
  auto errors = measure_levels(encoder, out->file, reference, sizes, mips, request);
  if (!errors) return errors.error();
  out->level_error = std::move(*errors);
  return out;
}

}  // namespace matbake::delivery
