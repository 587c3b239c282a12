// What a job holds and does, from what it decodes, makes and writes. The memory a cluster is asked
// for, from what it holds at its peak: every image is float samples, so a job's images cost 4 bytes
// a channel a texel (docs/cluster.md, "Memory model"; scripts/bench-cluster.sh measures it against
// peaks). Its work, for a progress display's ETA: texels decoded and written, rays, textures encoded.
#include <algorithm>
#include <cmath>
#include <set>

#include "../gltf/document.hpp"
#include "matbake/build_progress.hpp"
#include "matbake/cluster.hpp"
#include "matbake/image.hpp"
#include "matbake/workflow_maps.hpp"
#include "state.hpp"

namespace matbake::pipeline {
namespace fs = std::filesystem;
namespace {

constexpr double kMiB = 1024.0 * 1024.0;
constexpr double kProgramBytes = 32 * kMiB;  // the program and its libraries, nothing loaded
constexpr double kSampleBytes = 4;           // a float
// Per texel of a material: row buffers of the PNG writer, validation's classes.
constexpr double kWorkingBytesPerTexel = 16;
// A workflow conversion's new maps: the larger direction (kd, ks, gloss: 7 channels).
constexpr int kConversionChannels = 7;
// What a scene writes for a material with no layout: base colour + alpha, ORM, normal, emissive.
constexpr int kGltfMaterialChannels = 13;
// A glTF's own image: decoded RGBA, converted (workflow, ORM) and written.
constexpr double kOwnImageBytesPerTexel = 3 * 4 * kSampleBytes;
// An AO texture being baked: its value, coverage and samples' sums (bake_ao/textures.cpp).
constexpr double kAoBytesPerTexel = 24;
// A scene's geometry: each buffer as read, the meshes as triangles and Embree's BVH over them.
constexpr double kGeometryPerBufferByte = 8;
constexpr double kCompressedGeometryPerBufferByte = 32;  // Draco or meshopt: decoded first
// KTX2 delivery first decodes every texture the scene uses (RGBA float); a manifest material gives
// the glTF at most 4 (base colour, ORM, normal, emissive).
constexpr double kDecodedTextureBytesPerTexel = 4 * kSampleBytes;
constexpr int kGltfMaterialTextures = 4;
// KTX2 per texture encoded at once: matbake's level 0, mip chain and the PNG it hands over, with
// measure_levels the copy of the source its levels are measured against (RGBA float), then basisu's
// own (ETC1S at 2048² peaked at 64.5 bytes a texel, UASTC with RDO at 21).
constexpr double kKtx2ParentBytesPerTexel = 80;
constexpr double kMeasuredSourceBytesPerTexel = 4 * kSampleBytes;
constexpr double kBasisuBytesPerTexel = 72;

// Work rates (seconds on the 2-core reference machine, measured on the example's jobs): only their
// ratios matter, a display scales them by the run's own pace.
constexpr double kDecodeSecondsPerTexel = 8e-9;     // a PNG source, decoded
constexpr double kValidateSecondsPerTexel = 30e-9;  // F0 classes and flags
constexpr double kConvertSecondsPerTexel = 4e-6;    // spec-gloss ⇄ metal-rough (least squares)
constexpr double kWriteSecondsPerSample = 6e-9;     // a channel of a PNG written
constexpr double kRaySeconds = 5e-8;                // an AO ray (20 M rays/s)
constexpr double kKtx2SecondsPerTexel = 1e-6;       // basisu's chain, UASTC and ETC1S alike
constexpr double kGeometrySecondsPerByte = 2e-9;    // a scene's buffers read, written

// A scene's bake (bake/bake.cpp), per material of the low-poly: each map's floats, kept until they
// are written; while a material is traced, its texel positions (ao/texels' SurfacePoint) and per
// texel the sums of its hits (TexelSum), run index, hit flags and the fill's nearest-texel transform.
constexpr double kBakeBytesPerPoint = 20;
constexpr double kBakeBytesPerTexel = 200;

constexpr double kHeadroom = 1.25;
constexpr std::int64_t kMemoryStepMb = 64;

// Inputs that are never images: the scene files, the layout and table files.
bool may_be_image(const fs::path& file) {
  const std::string ext = file.extension().string();
  return ext != ".gltf" && ext != ".glb" && ext != ".bin" && ext != ".json" && ext != ".toml";
}

struct ImageSize {
  double texels = 0;
  int channels = 0;
};

ImageSize probe(const fs::path& file) {
  if (!may_be_image(file)) return {};
  auto info = image::probe_image(file);
  if (!info) return {};
  return {double(info->width) * double(info->height), info->channels};
}

// The texels a material's maps have (its largest source, or its size when every source is a
// constant) and the channels of its decoded files and of its maps.
struct MaterialShape {
  double texels = 1;
  int file_channels = 0;
  int map_channels = 0;
};

MaterialShape material_shape(const MaterialSpec& m) {
  MaterialShape shape;
  for (const fs::path& f : decoded_files(m)) {
    const ImageSize size = probe(f);
    shape.texels = std::max(shape.texels, size.texels);
    shape.file_channels += size.channels;
  }
  shape.texels = std::max(shape.texels, double(std::max(1, m.options.width)) * double(std::max(1, m.options.height)));
  for (const pack::SourceInput& s : m.sources) {
    if (const material::Source* source = material::find_source(s.name)) shape.map_channels += material::component_count(source->kind);
  }
  if (m.packed) shape.map_channels += shape.file_channels;  // a packed file's channels are its maps'
  return shape;
}

int texture_channels(const pack::Layout& layout) {
  int channels = 0;
  for (const pack::Texture& t : layout.textures) channels += int(t.channels.size());
  return channels;
}

// A material's images at their peak: files, maps, a conversion's maps, the textures it writes.
double material_bytes(const MaterialSpec& m, const MaterialShape& shape, int written_channels) {
  int channels = shape.file_channels + shape.map_channels + written_channels;
  if (m.layout && workflow::layout_direction(source_map_names(m), m.layout->layout)) channels += kConversionChannels;
  return shape.texels * (kSampleBytes * channels + kWorkingBytesPerTexel);
}

std::size_t array_size(const gltf::Json& json, const char* key) {
  return json.contains(key) && json[key].is_array() ? json[key].size() : 0;
}

bool uses_extension(const gltf::Json& json, const std::string& name) {
  if (!json.contains("extensionsUsed") || !json["extensionsUsed"].is_array()) return false;
  for (const auto& e : json["extensionsUsed"]) {
    if (e.is_string() && e.get<std::string>() == name) return true;
  }
  return false;
}

double buffer_bytes(const gltf::Json& json) {
  double bytes = 0;
  if (json.contains("buffers") && json["buffers"].is_array()) {
    for (const auto& b : json["buffers"]) {
      if (b.is_object() && b.contains("byteLength") && b["byteLength"].is_number()) bytes += std::max(0.0, b["byteLength"].get<double>());
    }
  }
  return bytes;
}

double geometry_bytes(const gltf::Json& json) {
  const bool compressed = uses_extension(json, "KHR_draco_mesh_compression") || uses_extension(json, "EXT_meshopt_compression");
  return buffer_bytes(json) * (compressed ? kCompressedGeometryPerBufferByte : kGeometryPerBufferByte);
}

// The vertices of the meshes (each mesh once, however often it is placed): per-vertex AO's rays.
double mesh_vertices(const gltf::Json& json) {
  if (!json.contains("meshes") || !json["meshes"].is_array() || !json.contains("accessors") || !json["accessors"].is_array()) return 0;
  const gltf::Json& accessors = json["accessors"];
  double vertices = 0;
  for (const auto& mesh : json["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (const auto& p : mesh["primitives"]) {
      if (!p.is_object() || !p.contains("attributes") || !p["attributes"].is_object()) continue;
      const auto position = p["attributes"].find("POSITION");
      if (position == p["attributes"].end() || !position->is_number_unsigned() || position->get<std::size_t>() >= accessors.size()) continue;
      const gltf::Json& a = accessors[position->get<std::size_t>()];
      if (a.is_object() && a.contains("count") && a["count"].is_number()) vertices += std::max(0.0, a["count"].get<double>());
    }
  }
  return vertices;
}

JobFootprint material_footprint(const MaterialSpec& m) {
  JobFootprint f;
  f.program = kProgramBytes;
  f.images = material_bytes(m, material_shape(m), m.layout ? texture_channels(m.layout->layout) : 0);
  return f;
}

// What a scene job reads: its manifest materials (each source's header read once) and its glTF's
// own images, and the glTF's JSON.
struct SceneInputs {
  double material_images = 0;    // the materials' images at their peak (material_bytes)
  double own_images = 0;         // the glTF's own images, decoded, converted and written
  double decoded_texels = 0;     // of every file decoded
  double largest_texture = 0;
  double delivered_texels = 0;   // of the textures the scene writes
  double converted_texels = 0;   // of materials converted to metal-rough (their maps are spec-gloss)
  std::optional<gltf::Json> json;
};

SceneInputs scene_inputs(const Job& job, const Manifest& manifest) {
  SceneInputs in;
  std::set<std::size_t> materials;
  std::set<fs::path> material_files;
  for (const auto& [gltf_name, m] : job.materials) materials.insert(m);
  for (std::size_t m : materials) {
    const MaterialSpec& spec = manifest.materials[m];
    const int written = spec.layout ? std::max(kGltfMaterialChannels, texture_channels(spec.layout->layout)) : kGltfMaterialChannels;
    const MaterialShape shape = material_shape(spec);
    in.material_images += material_bytes(spec, shape, written);
    in.largest_texture = std::max(in.largest_texture, shape.texels);
    in.delivered_texels += kGltfMaterialTextures * shape.texels;
    in.decoded_texels += shape.texels * double(std::max<std::size_t>(1, decoded_files(spec).size()));
    const material::MapNames names = source_map_names(spec);  // spec-gloss maps: a scene converts them
    if (names.count(material::kKd) && names.count(material::kGloss)) in.converted_texels += shape.texels;
    for (const fs::path& file : decoded_files(spec)) material_files.insert(file);
  }
  for (const fs::path& file : job.inputs) {
    if (material_files.count(fs::absolute(file).lexically_normal())) continue;
    const ImageSize size = probe(file);
    in.own_images += size.texels * kOwnImageBytesPerTexel;
    in.largest_texture = std::max(in.largest_texture, size.texels);
    in.delivered_texels += size.texels;
    in.decoded_texels += size.texels;
  }
  if (auto json = gltf::read_json(manifest.scenes[job.spec].input)) in.json = std::move(*json);
  return in;
}

// One AO texture per material, and per placement of a mesh when each gets its own.
double ao_textures(const ao::TextureRequest& t, const std::optional<gltf::Json>& json) {
  double textures = double(std::max<std::size_t>(1, json ? array_size(*json, "materials") : 1));
  if (t.per_instance && json) textures += double(array_size(*json, "nodes"));
  return textures;
}

// A scene's bake: one texture set per material of the low-poly, the maps' channels, and the maps
// that become the material's own textures (normal, ao, transfer: decoded again by the export).
struct BakeShape {
  double targets = 0, texels = 0, channels = 0, slot_maps = 0, high_geometry = 0;
  int tracers = 1;  // BVHs of the high-poly: the cage's, AO's, thickness's
};

BakeShape bake_shape(const SceneBake& b, const std::optional<gltf::Json>& low) {
  BakeShape shape;
  shape.targets = double(std::max<std::size_t>(1, low ? array_size(*low, "materials") : 1));
  shape.texels = double(b.request.texture.width) * double(b.request.texture.height);
  for (bake::Map m : b.request.bake.maps) {
    shape.channels += bake::channels(m);
    if (m == bake::Map::normal || m == bake::Map::ao || m == bake::Map::transfer) ++shape.slot_maps;
    if (m == bake::Map::thickness) ++shape.tracers;
  }
  const auto& maps = b.request.bake.maps;
  if (std::find(maps.begin(), maps.end(), bake::Map::ao) != maps.end() ||
      std::find(maps.begin(), maps.end(), bake::Map::bent_normal) != maps.end()) {
    ++shape.tracers;
  }
  if (auto high = gltf::read_json(b.high)) shape.high_geometry = geometry_bytes(*high);
  return shape;
}

JobFootprint scene_footprint(const Job& job, const Manifest& manifest, int cpus) {
  const SceneSpec& s = manifest.scenes[job.spec];
  const SceneInputs in = scene_inputs(job, manifest);
  JobFootprint f;
  f.program = kProgramBytes;
  f.images = in.material_images + in.own_images;
  if (in.json) f.geometry = geometry_bytes(*in.json);
  if (s.options.ao && s.options.ao->texture) {
    const ao::TextureRequest& t = *s.options.ao->texture;
    f.ao = ao_textures(t, in.json) * double(t.size.width) * double(t.size.height) * kAoBytesPerTexel;
  }
  double delivered_texels = in.delivered_texels, largest_texture = in.largest_texture;
  if (s.bake) {
    const BakeShape b = bake_shape(*s.bake, in.json);
    f.geometry += b.high_geometry * b.tracers;
    f.ao += b.texels * (b.targets * b.channels * kSampleBytes + s.bake->request.texture.texel_samples * kBakeBytesPerPoint +
                        kBakeBytesPerTexel);
    f.images += b.targets * b.slot_maps * b.texels * kOwnImageBytesPerTexel;  // the export reads them as its own
    delivered_texels += b.targets * b.slot_maps * b.texels;
    largest_texture = std::max(largest_texture, b.slot_maps > 0 ? b.texels : 0.0);
  }
  if (s.options.delivery.texture_format == delivery::TextureFormat::ktx2) {
    // Every texture decoded, then encoded in parallel, one per core: the largest, that many at once.
    const double parent = kKtx2ParentBytesPerTexel + (s.options.delivery.measure_levels ? kMeasuredSourceBytesPerTexel : 0);
    f.encoder = delivered_texels * kDecodedTextureBytesPerTexel +
                double(std::max(1, cpus)) * largest_texture * (parent + kBasisuBytesPerTexel);
  }
  return f;
}

JobWork material_work(const MaterialSpec& m) {
  const MaterialShape shape = material_shape(m);
  JobWork w;
  w.read = shape.texels * double(std::max<std::size_t>(1, decoded_files(m).size())) * kDecodeSecondsPerTexel;
  if (m.validation.enabled) w.textures += shape.texels * kValidateSecondsPerTexel;
  if (m.layout) {
    w.textures += shape.texels * texture_channels(m.layout->layout) * kWriteSecondsPerSample;
    if (workflow::layout_direction(source_map_names(m), m.layout->layout)) w.textures += shape.texels * kConvertSecondsPerTexel;
  }
  return w;
}

JobWork scene_work(const Job& job, const Manifest& manifest) {
  const SceneSpec& s = manifest.scenes[job.spec];
  const SceneInputs in = scene_inputs(job, manifest);
  const double geometry = in.json ? buffer_bytes(*in.json) : 0;
  JobWork w;
  w.read = in.decoded_texels * kDecodeSecondsPerTexel + in.converted_texels * kConvertSecondsPerTexel +
           geometry * kGeometrySecondsPerByte;
  if (s.options.ao) {
    const double samples = double(s.options.ao->options.samples);
    if (const auto& t = s.options.ao->texture) {
      w.ao = ao_textures(*t, in.json) * double(t->size.width) * double(t->size.height) * samples * kRaySeconds;
    } else if (in.json) {
      w.ao = mesh_vertices(*in.json) * samples * kRaySeconds;
    }
  }
  double delivered_texels = in.delivered_texels;
  if (s.bake) {
    // A ray per texel position; AO's (shared by the bent normal) and thickness's rays per texel.
    const BakeShape b = bake_shape(*s.bake, in.json);
    const double rays_per_texel = s.bake->request.texture.texel_samples +
                                  (b.tracers - 1) * double(s.bake->request.occlusion.options.samples);
    w.ao += b.targets * b.texels * rays_per_texel * kRaySeconds;
    delivered_texels += b.targets * b.slot_maps * b.texels;
  }
  const bool ktx2 = s.options.delivery.texture_format == delivery::TextureFormat::ktx2;
  w.textures = delivered_texels * (ktx2 ? kKtx2SecondsPerTexel : 4 * kWriteSecondsPerSample);
  w.write = geometry * kGeometrySecondsPerByte;
  return w;
}

}  // namespace

JobFootprint job_footprint(const Job& job, const Manifest& manifest, int cpus) {
  if (job.kind == JobKind::material) return material_footprint(manifest.materials[job.spec]);
  return scene_footprint(job, manifest, cpus);
}

JobWork job_work(const Job& job, const Manifest& manifest) {
  if (job.kind == JobKind::material) return material_work(manifest.materials[job.spec]);
  return scene_work(job, manifest);
}

std::int64_t memory_request_mb(const JobFootprint& footprint) {
  const double mb = footprint.total() / kMiB * kHeadroom;
  return std::int64_t(std::ceil(mb / double(kMemoryStepMb))) * kMemoryStepMb;
}

}  // namespace matbake::pipeline
