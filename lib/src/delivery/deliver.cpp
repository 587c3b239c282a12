// The delivery pass: find each used texture's class, decode its image once, then (in parallel, each
// texture its own task) resize or make its mip chain and encode it, then rewrite the document in
// texture order, so that the written bytes do not depend on the thread count.
#include "deliver.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "../scene/from_document.hpp"
#include "../gltf/prune.hpp"
#include "../gltf/texture_transform.hpp"
#include "encode_cache.hpp"
#include "matbake/ktx2.hpp"
#include "matbake/version.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
using gltf::Json;
namespace {

constexpr const char* kBasisu = "KHR_texture_basisu";
constexpr const char* kWebp = "EXT_texture_webp";

// A material slot reading a texture: through which texCoord set, and how much its
// KHR_texture_transform scales UV area (|scale.x · scale.y|; rotation and offset keep area), so
// that a texture tiled 3× needs a third of the side per direction.
struct Placement {
  int material = -1;
  int texcoord = 0;
  double uv_area_scale = 1;
  auto operator<=>(const Placement&) const = default;
};

struct Use {
  TextureClass texture_class = TextureClass::colour;
  std::optional<float> alpha_cutoff;
  std::string conflict;  // "used as colour and data": kept as it is
  std::set<Placement> placements;  // every slot that reads it
  int first_material = -1;          // the first slot that reads it, which names it when its image has no name
  std::string first_slot;           // "baseColorTexture"
};

void record(std::map<int, Use>& uses, int texture, TextureClass c, std::optional<float> cutoff, Placement placement,
            const std::string& slot) {
  auto [it, fresh] = uses.try_emplace(texture, Use{c, cutoff, "", {}, placement.material, slot});
  Use& use = it->second;
  use.placements.insert(placement);
  if (fresh) return;
  if (use.texture_class != c && use.conflict.empty()) {
    use.conflict = "used as " + std::string(name_in(kTextureClassNames, use.texture_class)) + " and " +
                   std::string(name_in(kTextureClassNames, c)) + ": kept as it is";
  }
  if (!use.alpha_cutoff) use.alpha_cutoff = cutoff;
}

// How a textureInfo reads its texture. A malformed transform counts as none here (the export
// reports it where it resamples through it).
Placement placement_of(const Json& info, int material) {
  Placement p{material, gltf::integer_in<int>(info, "texCoord", 0, -1), 1};
  if (auto transform = gltf::uv_transform_of(info, "", "")) {
    if (transform->texcoord >= 0) p.texcoord = transform->texcoord;
    p.uv_area_scale = std::abs(transform->scale.x * transform->scale.y);
  }
  return p;
}

// Every textureInfo under `node` (a material, its extensions): {"index": n} under a key "...Texture".
void collect(const Json& node, int material, std::optional<float> cutoff, std::map<int, Use>& uses) {
  if (!node.is_object()) return;
  for (const auto& [key, value] : node.items()) {
    if (!value.is_object()) continue;
    if (key.ends_with("Texture") && value.contains("index")) {
      const int index = gltf::integer_in<int>(value, "index", -1, -1);
      const bool mask_alpha = key == "baseColorTexture";
      if (index >= 0) record(uses, index, class_of_slot(key), mask_alpha ? cutoff : std::nullopt, placement_of(value, material), key);
    } else {
      collect(value, material, cutoff, uses);
    }
  }
}

std::map<int, Use> texture_uses(const Json& json) {
  std::map<int, Use> uses;
  int index = 0;
  for (const Json& material : gltf::array_in(json, "materials")) {
    const int m = index++;
    if (!material.is_object()) continue;
    std::optional<float> cutoff;
    if (material.value("alphaMode", "") == "MASK") {
      const auto it = material.find("alphaCutoff");
      cutoff = it != material.end() && it->is_number() ? it->get<float>() : 0.5f;
    }
    collect(material, m, cutoff, uses);
  }
  return uses;
}

// The image a texture's texels come from: its core source, else its WebP one; −1 when it has only
// KTX2 (or none).
int decodable_image(const Json& texture) {
  if (const int core = gltf::integer_in<int>(texture, "source", -1, -1); core >= 0) return core;
  if (texture.contains("extensions") && texture["extensions"].contains(kWebp)) {
    return gltf::integer_in<int>(texture["extensions"][kWebp], "source", -1, -1);
  }
  return -1;
}

Sampling sampling_of(const Json& json, const Json& texture, Filter filter) {
  Sampling s{.filter = filter};
  const int sampler = gltf::integer_in<int>(texture, "sampler", -1, -1);
  const Json& samplers = gltf::array_in(json, "samplers");
  if (sampler >= 0 && std::size_t(sampler) < samplers.size()) {
    s.wrap_s = wrap_from_gltf(gltf::integer_in<int>(samplers[std::size_t(sampler)], "wrapS", 10497, 10497));
    s.wrap_t = wrap_from_gltf(gltf::integer_in<int>(samplers[std::size_t(sampler)], "wrapT", 10497, 10497));
  }
  return s;
}

// A file name for what replaces image `image`: its file's stem, else its name, else its first
// material's and slot's ("Paint_baseColor"); only characters safe in a URI.
std::string base_name(const Json& json, int image, const Use& use) {
  const Json& img = gltf::array_in(json, "images")[std::size_t(image)];
  std::string name;
  if (img.contains("uri") && img["uri"].is_string() && img["uri"].get<std::string>().rfind("data:", 0) != 0) {
    name = fs::path(gltf::decode_uri(img["uri"].get<std::string>())).stem().string();
  } else {
    name = gltf::name_in(img, "");
  }
  name = gltf::uri_safe(name);
  if (!name.empty()) return name;
  const std::string slot = use.first_slot.substr(0, use.first_slot.rfind("Texture"));
  return gltf::material_file_name(gltf::array_in(json, "materials")[std::size_t(use.first_material)], use.first_material) + "_" + slot;
}

double triangle_area(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) { return 0.5 * glm::length(glm::cross(b - a, c - a)); }

// Each used texture's triangles as the scene places them (world area, UV area of the texCoord set
// each material reads it with).
Result<std::map<int, std::vector<MappedTriangle>>> mapped_triangles(const gltf::Document& doc, const std::map<int, Use>& uses) {
  auto scene = scene::scene_from_document(doc, {.texcoords = true});
  if (!scene) return scene.error();
  std::map<int, std::vector<MappedTriangle>> out;
  for (const scene::Instance& instance : scene->instances) {
    for (const auto& [texture, use] : uses) {
      for (const auto& [material, texcoord, uv_area_scale] : use.placements) {
        if (material != instance.material || texcoord < 0 || std::size_t(texcoord) >= instance.texcoords.size()) continue;
        const std::vector<glm::vec2>& uv = instance.texcoords[std::size_t(texcoord)];
        if (uv.size() != instance.positions.size()) continue;
        for (const auto& t : instance.triangles) {
          const auto& p = instance.positions;
          const double uv_area =
              0.5 * std::abs(double(uv[t[1]].x - uv[t[0]].x) * double(uv[t[2]].y - uv[t[0]].y) -
                             double(uv[t[2]].x - uv[t[0]].x) * double(uv[t[1]].y - uv[t[0]].y));
          out[texture].push_back({triangle_area(p[t[0]], p[t[1]], p[t[2]]), uv_area * uv_area_scale});
        }
      }
    }
  }
  return out;
}

// One texture's work: what it is made from, and what was made.
struct Work {
  int texture = -1, image = -1;
  Use use;
  Sampling sampling;
  color::Transfer transfer = color::Transfer::linear;  // how its image is decoded (sRGB for colour)
  Size source_size;
  Size size;
  std::optional<int> needed;
  Codec codec = Codec::png;
  std::string name;
  int made_by = -1;  // the index in the work list of the alike texture that makes this one's file
  std::string shared_note;  // set when textures made once had differing wrap modes
  // Made:
  std::vector<unsigned char> file;  // the KTX2 file, or (codec png) the resized texture's PNG or WebP
  int levels = 1;
  std::vector<double> coverage;
  std::vector<LevelError> level_error;
  double seconds = 0;   // decoding and making it
  bool reused = false;  // from the encode cache
  bool cache_rejected = false;  // an entry under its key failed its content hash: made again
  Status status = success();
};

// KHR_texture_basisu: "pixelWidth and pixelHeight MUST be multiples of 4". A side below 4 (a 1 × 1
// constant, a 2 × 2 swatch) is raised to 4, the one case where a delivered side exceeds its source.
// Whether the texture's file is made by its own work (not an alike one's, and not kept as it is).
bool makes(const Work& w) { return w.made_by < 0 && !(w.codec == Codec::png && w.size == w.source_size); }

Size ktx2_size(Size s) { return {std::max(s.width, 4), std::max(s.height, 4)}; }
bool sides_fit_ktx2(Size s) { return s.width % 4 == 0 && s.height % 4 == 0; }

// The resized texture of `source` as the cache's format (PNG or WebP) makes it.
Result<Encoded> resized_file(const Work& w, const image::Image& source, const MipRequest& request, const gltf::ImageCache& cache) {
  const image::Image level0 = std::move(mip_chain(source, w.size, request, false)[0]);
  Encoded made{.levels = 1};
  if (w.use.alpha_cutoff) made.coverage = {alpha_coverage(source, *w.use.alpha_cutoff), alpha_coverage(level0, *w.use.alpha_cutoff)};
  auto bytes = cache.encode(level0, w.transfer, w.name);
  if (!bytes) return bytes.error();
  made.file.assign(bytes->begin(), bytes->end());
  return made;
}

Status make(Work& w, image::Image source, const Options& options, const gltf::ImageCache& cache, const Encoder* encoder,
            const fs::path& output, int threads) {
  const MipRequest request{w.use.texture_class, w.sampling, w.use.alpha_cutoff, options.keep_alpha_coverage};
  const EncodeCache kept{options.encode_cache, options.encode_cache_bytes};
  Result<Encoded> made = Error{"", "not made"};
  if (w.codec == Codec::png) {
    const std::string key =
        kept.on() ? made_file_key(source, w.size, request, cache.webp() ? "webp" : "png", cache.png_level(), "matbake " + std::string(matbake::version))
              : std::string();
    made = through_cache(kept, key, w.size, [&] { return resized_file(w, source, request, cache); }, w.reused,
                         &w.cache_rejected);
  } else {
    EncodeRequest encode{.texture_class = w.use.texture_class, .options = options.of(w.use.texture_class), .sampling = w.sampling,
                         .mipmaps = options.mipmaps, .alpha = has_alpha(source),
                         .scratch = output.parent_path() / (w.name + ".ktx2"), .threads = threads,
                         .measure_levels = options.measure_levels};
    made = encode_with_cache(kept, *encoder, std::move(source), w.size, request, encode,
                             "matbake " + std::string(matbake::version) + " / basisu " + encoder->version, w.reused, &w.cache_rejected);
  }
  if (!made) return made.error();
  w.file = std::move(made->file);
  w.levels = made->levels;
  w.coverage = std::move(made->coverage);
  w.level_error = std::move(made->level_error);
  return success();
}

// Textures made alike (one image, class, size, codec, alpha cutoff and mip filter) are made once, as
// gltfpack and glTF-Transform store an image once whatever samplers read it: each later one is
// marked made by the first. The first's mip edges follow the wrap mode all of them agree on per axis,
// clamp to edge where they differ (which reads no texel of the opposite edge, wrong for none of
// them by more than an edge texel's filter footprint); the textures' reports say so.
void make_alike_once(std::vector<Work>& work) {
  for (std::size_t i = 0; i < work.size(); ++i) {
    Work& w = work[i];
    for (std::size_t first = 0; first < i; ++first) {
      Work& f = work[first];
      if (f.made_by >= 0 || f.image != w.image || f.use.texture_class != w.use.texture_class || f.size != w.size ||
          f.codec != w.codec || f.use.alpha_cutoff != w.use.alpha_cutoff || f.sampling.filter != w.sampling.filter) {
        continue;
      }
      w.made_by = int(first);
      if (f.sampling.wrap_s != w.sampling.wrap_s || f.sampling.wrap_t != w.sampling.wrap_t) {
        if (f.sampling.wrap_s != w.sampling.wrap_s) f.sampling.wrap_s = Wrap::clamp_to_edge;
        if (f.sampling.wrap_t != w.sampling.wrap_t) f.sampling.wrap_t = Wrap::clamp_to_edge;
        f.shared_note = "one file with the other textures of image '" + f.name + "': their samplers' wrap modes differ, so "
                        "its mip levels' edges are filtered as clamp to edge";
      }
      break;
    }
  }
  for (Work& w : work) {
    if (w.made_by >= 0) w.shared_note = work[std::size_t(w.made_by)].shared_note;
  }
}

// The texture's sources replaced: KTX2 through KHR_texture_basisu (its PNG or WebP source kept only
// as a fallback), or the resized image in place of the old one.
void point_texture(gltf::Document& doc, const Work& w, int image, bool png_fallback) {
  Json& texture = doc.json["textures"][std::size_t(w.texture)];
  if (w.codec == Codec::png) {
    if (texture.contains("source")) texture["source"] = image;
    else texture["extensions"][kWebp]["source"] = image;
    return;
  }
  texture["extensions"][kBasisu] = Json{{"source", image}};
  if (!png_fallback) {
    texture.erase("source");
    texture["extensions"].erase(kWebp);
  }
}

// A KTX2 file of one level (`--no-mipmaps`) under a mipmapped sampler makes runtimes fall back (three.js
// samples a chain it does not have): the texture gets a sampler like its own with the minification
// filter of the same kind without mipmaps, shared with any texture that needs the same.
void sample_one_level(gltf::Document& doc, int texture_index) {
  constexpr int kNearest = 9728, kLinear = 9729, kNearestMipmapNearest = 9984, kNearestMipmapLinear = 9986;
  Json& texture = doc.json["textures"][std::size_t(texture_index)];
  const int index = gltf::integer_in<int>(texture, "sampler", -1, -1);
  const Json& given = gltf::array_in(doc.json, "samplers");
  Json sampler = index >= 0 && std::size_t(index) < given.size() ? given[std::size_t(index)] : Json::object();
  const int min_filter = gltf::integer_in<int>(sampler, "minFilter", -1, -1);
  if (min_filter == kNearest || min_filter == kLinear) return;
  const bool nearest = min_filter == kNearestMipmapNearest || min_filter == kNearestMipmapLinear;
  sampler["minFilter"] = nearest ? kNearest : kLinear;
  Json& samplers = doc.json["samplers"];
  const auto same = std::find(samplers.begin(), samplers.end(), sampler);
  if (same != samplers.end()) {
    texture["sampler"] = int(same - samplers.begin());
    return;
  }
  samplers.push_back(sampler);
  texture["sampler"] = int(samplers.size()) - 1;
}

// The file `made` made, as a new image of `doc` (KTX2, or the resized texture as PNG or WebP); its index.
int add_made_image(gltf::Document& doc, const gltf::ImageCache& cache, const Work& made) {
  std::string bytes(made.file.begin(), made.file.end());
  if (made.codec != Codec::png) {
    const std::string uri = gltf::free_uri(doc, made.name, ".ktx2");
    doc.new_files[uri] = std::move(bytes);
    doc.json["images"].push_back({{"uri", uri}, {"mimeType", "image/ktx2"}, {"name", fs::path(uri).stem().string()}});
    return int(doc.json["images"].size()) - 1;
  }
  const std::string size = std::to_string(made.size.width) + "x" + std::to_string(made.size.height);
  return cache.add_encoded(doc, std::move(bytes), made.name + "_" + size).index;
}

// EXT_texture_webp named only while a texture still uses it.
void drop_unused_webp(gltf::Document& doc) {
  for (const Json& t : gltf::array_in(doc.json, "textures")) {
    if (t.contains("extensions") && t["extensions"].contains(kWebp)) return;
  }
  for (const char* list : {"extensionsUsed", "extensionsRequired"}) {
    if (!doc.json.contains(list)) continue;
    Json& names = doc.json[list];
    names.erase(std::remove(names.begin(), names.end(), kWebp), names.end());
    if (names.empty()) doc.json.erase(list);
  }
}

std::vector<int> materials_of(const Use& use) {
  std::vector<int> out;
  for (const Placement& p : use.placements) {
    if (out.empty() || out.back() != p.material) out.push_back(p.material);
  }
  return out;
}

// Each used texture's work (class, sizes, codec, name), before any texel is decoded; a texture kept
// as it is (already KTX2, used as two classes) goes to `kept` with the reason.
Result<std::vector<Work>> planned_work(const gltf::Document& doc, const gltf::ImageCache& cache, const Options& options,
                                       std::vector<TextureReport>& kept) {
  const bool ktx2_out = options.texture_format == TextureFormat::ktx2;
  std::vector<Work> work;
  const std::map<int, Use> uses = texture_uses(doc.json);
  std::map<int, std::vector<MappedTriangle>> mapped;
  if (options.texel_density > 0) {
    auto found = mapped_triangles(doc, uses);
    if (!found) return found.error();
    mapped = std::move(*found);
  }
  for (const auto& [texture, use] : uses) {
    const Json& t = doc.json["textures"][std::size_t(texture)];
    const int image = decodable_image(t);
    if (image < 0 || !use.conflict.empty()) {
      kept.push_back({.texture = texture, .texture_class = use.texture_class, .materials = materials_of(use),
                      .alpha_cutoff = use.alpha_cutoff,
                      .note = !use.conflict.empty() ? use.conflict : "no PNG, JPEG or WebP source (already KTX2): kept as it is"});
      continue;
    }
    const color::Transfer transfer = use.texture_class == TextureClass::colour ? color::Transfer::srgb : color::Transfer::linear;
    // Its size from the image's header (a header that does not read fails the pass before any
    // encode); decoded when its turn comes, so that only the textures being worked on are held.
    Size source_size;
    if (auto size = cache.size_of(texture); size) {
      source_size = {size->first, size->second};
    } else {
      return size.error();
    }
    Work w{.texture = texture, .image = image, .use = use, .sampling = sampling_of(doc.json, t, options.filter),
           .transfer = transfer, .source_size = source_size};
    const ClassOptions& o = options.of(use.texture_class);
    if (options.texel_density > 0) w.needed = needed_side(mapped[texture], source_size, options.texel_density);
    w.size = delivered_size(source_size, o, options.rounding, w.needed);
    w.codec = ktx2_out ? o.codec : Codec::png;
    w.name = base_name(doc.json, image, use);
    if (w.codec != Codec::png) w.size = ktx2_size(w.size);
    if (w.codec != Codec::png && !sides_fit_ktx2(w.size)) {
      return Error{doc.file, "texture " + std::to_string(texture) + " (" + w.name + ") would be " + std::to_string(w.size.width) +
                                 "x" + std::to_string(w.size.height) + ": KTX2 (KHR_texture_basisu) needs sides that are multiples "
                                 "of 4; use " + mention("texture_rounding", "multiple-of-4") + " or power-of-two", true};
    }
    work.push_back(std::move(w));
  }
  make_alike_once(work);
  return work;
}

}  // namespace

TextureClass class_of_slot(const std::string& key) {
  if (key.find("ormalTexture") != std::string::npos) return TextureClass::normal;
  if (key == "baseColorTexture" || key == "emissiveTexture" || key.ends_with("ColorTexture")) return TextureClass::colour;
  return TextureClass::data;
}


bool changes_textures(const Options& options) {
  if (options.texture_format == TextureFormat::ktx2 || options.texel_density > 0) return true;
  for (TextureClass c : {TextureClass::colour, TextureClass::data, TextureClass::normal}) {
    if (options.of(c).max_size > 0 || options.of(c).scale != 1) return true;
  }
  return false;
}

gltf::MadeFormat made_format(const Options& options) {
  return options.texture_format == TextureFormat::webp ? gltf::MadeFormat::webp : gltf::MadeFormat::png;
}

Result<std::vector<TextureReport>> deliver_textures(gltf::Document& doc, gltf::ImageCache& cache, const Options& options,
                                                    const fs::path& output, const StageReport& stage) {
  if (!changes_textures(options)) return std::vector<TextureReport>{};
  const bool ktx2_out = options.texture_format == TextureFormat::ktx2;
  std::vector<TextureReport> reports;
  auto planned = planned_work(doc, cache, options, reports);
  if (!planned) return planned.error();
  std::vector<Work> work = std::move(*planned);
  cache.forget_decoded();  // the earlier passes' images: delivery decodes each texture in its turn
  const Encoder* encoder = nullptr;
  std::optional<Encoder> found;
  if (std::any_of(work.begin(), work.end(), [](const Work& w) { return w.codec != Codec::png; })) {
    auto e = find_encoder();
    if (!e) return e.error();
    found = std::move(*e);
    encoder = &*found;
  }
  // Textures in parallel. UASTC runs are single-threaded, as many at once as --jobs; an ETC1S run
  // (one at a time, encode.cpp) gets every thread.
  const int threads = tbb::this_task_arena::max_concurrency();
  const std::size_t to_make = std::size_t(std::count_if(work.begin(), work.end(), [](const Work& w) { return makes(w); }));
  std::atomic<std::size_t> textures_made{0};
  const auto tell = [&](std::size_t n) {
    report_stage(stage, Phase::textures, (ktx2_out ? "encoding textures " : "resizing textures ") + std::to_string(n) + " of " +
                                             std::to_string(to_make), to_make ? double(n) / double(to_make) : 1.0);
  };
  tell(0);
  tbb::parallel_for(std::size_t(0), work.size(), [&](std::size_t i) {
    Work& w = work[i];
    if (!makes(w)) return;  // made by another, or unchanged
    // Decoded in its turn and dropped when made. Not isolated: a thread waiting inside one texture's
    // encode may start another (isolating cost 15% of the wall time on SpecGlossVsMetalRough for the
    // same peak), so a few more than --jobs textures can be held at once.
    const auto start = std::chrono::steady_clock::now();
    w.status = guarded(doc.file, [&]() -> Status {
      auto source = cache.decode(w.texture, w.transfer);
      if (!source) return source.error();
      return make(w, std::move(*source), options, cache, encoder, output, threads);
    });
    w.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    tell(++textures_made);
  }, tbb::simple_partitioner());
  for (Work& w : work) {
    if (!w.status) return w.status.error();
  }

  std::vector<int> written(work.size(), -1);  // the image each made file was added as
  for (std::size_t i = 0; i < work.size(); ++i) {
    const Work& w = work[i];
    const Work& made = w.made_by >= 0 ? work[std::size_t(w.made_by)] : w;
    int& image = written[w.made_by >= 0 ? std::size_t(w.made_by) : i];
    TextureReport report{.texture = w.texture, .texture_class = w.use.texture_class, .codec = w.codec,
                         .source = w.source_size, .delivered = w.size, .needed = w.needed,
                         .materials = materials_of(w.use), .levels = made.levels,
                         .alpha_cutoff = w.use.alpha_cutoff, .coverage = made.coverage, .note = w.shared_note,
                         .reused = made.reused, .cache_rejected = made.cache_rejected, .level_error = made.level_error, .seconds = w.seconds};
    if (options.keep_alpha_coverage && options.mipmaps && w.use.alpha_cutoff && w.codec == Codec::etc1s) {
      report.note += std::string(report.note.empty() ? "" : "; ") +
                     "ETC1S levels are basisu's own: keep_alpha_coverage does not act on them (UASTC does)";
    }
    auto source_bytes = gltf::image_bytes(doc, std::size_t(w.image));
    if (!source_bytes) return source_bytes.error();
    report.source_bytes = source_bytes->size();
    report.bytes = report.source_bytes;
    if (made.file.empty()) {
      report.note = "kept as it is (its size and format are what was asked)";
      reports.push_back(std::move(report));
      continue;
    }
    if (image < 0) image = add_made_image(doc, cache, made);
    point_texture(doc, w, image, options.png_fallback);
    report.bytes = made.file.size();
    if (made.codec != Codec::png) {
      if (!options.mipmaps) sample_one_level(doc, w.texture);
      gltf::require_extension(doc, kBasisu, !options.png_fallback);
    }
    const Json& written_image = doc.json["images"][std::size_t(image)];
    report.uri = written_image["uri"].get<std::string>();
    doc.json["textures"][std::size_t(w.texture)]["name"] = written_image["name"];
    reports.push_back(std::move(report));
  }
  drop_unused_webp(doc);
  std::sort(reports.begin(), reports.end(), [](const TextureReport& a, const TextureReport& b) { return a.texture < b.texture; });
  return reports;
}

Result<std::vector<TextureReport>> plan_textures(const gltf::Document& doc, const gltf::ImageCache& cache, const Options& options) {
  std::vector<TextureReport> reports;
  auto planned = planned_work(doc, cache, options, reports);
  if (!planned) return planned.error();
  for (const Work& w : *planned) {
    TextureReport report{.texture = w.texture, .texture_class = w.use.texture_class, .codec = w.codec, .source = w.source_size,
                         .delivered = w.size, .needed = w.needed, .materials = materials_of(w.use),
                         .levels = w.codec != Codec::png && options.mipmaps ? int(mip_sizes(w.size).size()) : 1,
                         .alpha_cutoff = w.use.alpha_cutoff, .note = w.shared_note};
    auto source_bytes = gltf::image_bytes(doc, std::size_t(w.image));
    if (!source_bytes) return source_bytes.error();
    report.source_bytes = source_bytes->size();
    if (w.made_by >= 0) report.note = "one file with texture " + std::to_string((*planned)[std::size_t(w.made_by)].texture);
    report.bytes = w.made_by >= 0 ? 0 : estimated_bytes(report, options.of(w.use.texture_class));
    reports.push_back(std::move(report));
  }
  std::sort(reports.begin(), reports.end(), [](const TextureReport& a, const TextureReport& b) { return a.texture < b.texture; });
  return reports;
}

std::vector<std::string> store_once(gltf::Document& doc, std::vector<TextureReport>& reports) {
  const std::vector<int> same_as = gltf::merge_identical_images(doc);
  std::vector<int> remap;
  std::vector<std::string> removed = gltf::prune_unreachable(doc, &remap);
  std::vector<TextureReport> written;
  for (TextureReport& r : reports) {
    // A texture merged into another is reported as that one, its materials with it.
    if (r.texture >= 0 && std::size_t(r.texture) < same_as.size()) r.texture = same_as[std::size_t(r.texture)];
    if (r.texture < 0 || std::size_t(r.texture) >= remap.size() || remap[std::size_t(r.texture)] < 0) continue;
    r.texture = remap[std::size_t(r.texture)];
    const auto same = std::find_if(written.begin(), written.end(), [&](const TextureReport& w) { return w.texture == r.texture; });
    if (same == written.end()) {
      written.push_back(std::move(r));
      continue;
    }
    same->materials.insert(same->materials.end(), r.materials.begin(), r.materials.end());
    std::sort(same->materials.begin(), same->materials.end());
    same->materials.erase(std::unique(same->materials.begin(), same->materials.end()), same->materials.end());
  }
  std::sort(written.begin(), written.end(), [](const TextureReport& a, const TextureReport& b) { return a.texture < b.texture; });
  reports = std::move(written);
  return removed;
}

}  // namespace matbake::delivery
