#pragma once
// GPU-ready delivery of a glTF's textures (docs/delivery.md): each texture sized for its class (or
// from the texel density the scene needs), given a mip chain made here — every level from the base,
// colour in linear light, normals renormalised, alpha coverage kept for MASK materials — and
// written as KTX2 (KHR_texture_basisu) through Basis Universal's `basisu`, or kept as PNG.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "matbake/enum_names.hpp"
#include "matbake/image.hpp"
#include "matbake/wrap.hpp"

namespace matbake::delivery {

// What a texture holds, by the material slot that reads it: baseColor and emissive are colour
// (sRGB), metallic-roughness and occlusion (ORM) are data (linear, channels apart), normal is normal.
enum class TextureClass { colour, data, normal };
inline constexpr NameTable<TextureClass, 3> kTextureClassNames{
    {{TextureClass::colour, "colour"}, {TextureClass::data, "data"}, {TextureClass::normal, "normal"}}};

// The class of a material slot, by its key, for core and extension slots alike: normal maps
// (normalTexture, clearcoatNormalTexture), colour (baseColor, emissive, *ColorTexture: specular
// colour, sheen colour), data otherwise (metallic-roughness, occlusion, clearcoat, transmission...).
TextureClass class_of_slot(const std::string& key);

// How a class's textures are stored: Basis Universal ETC1S (small, BasisLZ), UASTC (high quality,
// optionally zstd-supercompressed), or PNG (kept, resized when the sizes say so).
enum class Codec { etc1s, uastc, png };
inline constexpr NameTable<Codec, 3> kCodecNames{{{Codec::etc1s, "etc1s"}, {Codec::uastc, "uastc"}, {Codec::png, "png"}}};

// How a delivered size is rounded: to a power of two, to a multiple of 4 (what KHR_texture_basisu
// needs; sides of 1 and 2 stay, and KTX2 delivery raises them to 4), or not at all. Never above the
// source but for that.
enum class Rounding { power_of_two, multiple_of_4, none };
inline constexpr NameTable<Rounding, 3> kRoundingNames{
    {{Rounding::power_of_two, "power-of-two"}, {Rounding::multiple_of_4, "multiple-of-4"}, {Rounding::none, "none"}}};

// The resampling filter of resizes and mip levels: a Kaiser-windowed sinc (radius 3 output texels,
// β = 4), or the box (each output texel the area-weighted mean of the source texels it covers).
enum class Filter { kaiser, box };
inline constexpr NameTable<Filter, 2> kFilterNames{{{Filter::kaiser, "kaiser"}, {Filter::box, "box"}}};

using matbake::Wrap;  // a sampler's wrap mode along one axis: where the filter reads past an edge

struct ClassOptions {
  Codec codec = Codec::uastc;
  int quality = 128;      // ETC1S: basisu -q, 1–255
  int uastc_level = 2;    // UASTC: basisu -uastc_level, 0–4
  double uastc_rdo = 0;   // UASTC: rate-distortion λ (basisu -uastc_rdo_l); 0: off
  int uastc_rdo_dictionary = 4096;  // UASTC RDO: bytes of history it searches (basisu -uastc_rdo_d), 64–65536
  int zstd = 18;          // UASTC: zstd supercompression level, 1–22; 0: none
  int max_size = 0;       // the longer side at most this (1–16384); 0: no limit
  double scale = 1;       // both sides times this (0 < scale ≤ 1)
};

// The format of the textures a glTF is delivered with: PNG, or lossless 8-bit WebP (the texture then
// names it through EXT_texture_webp, which the file requires), or KTX2: textures made as PNG, then
// every texture the scene uses encoded by its class's codec (KHR_texture_basisu).
enum class TextureFormat { png, webp, ktx2 };
inline constexpr NameTable<TextureFormat, 3> kTextureFormatNames{
    {{TextureFormat::png, "png"}, {TextureFormat::webp, "webp"}, {TextureFormat::ktx2, "ktx2"}}};

// How a glTF's meshes are delivered (docs/delivery.md, "Geometry"). Either setting on reorders each
// triangle list for the GPU's vertex cache and vertex fetch (meshoptimizer) first.
// quantize: KHR_mesh_quantization. POSITION as unsigned integers of position_bits on one uniform grid
// per mesh (the dequantizing translation and scale on a child node placing the mesh), NORMAL and
// TANGENT as normalized bytes, TEXCOORD_n as normalized shorts of texcoord_bits over the scene's range
// of that set (undone by KHR_texture_transform in the materials), COLOR_n as normalized bytes; what
// cannot be so (a skinned, morphed or instanced mesh's positions; UVs beyond [0, 1] no material's
// transform can take) stays as it was. compression meshopt: EXT_meshopt_compression on the vertex and
// index buffers (required: the file has no uncompressed copy).
enum class MeshCompression { none, meshopt };
inline constexpr NameTable<MeshCompression, 2> kMeshCompressionNames{{{MeshCompression::none, "none"}, {MeshCompression::meshopt, "meshopt"}}};

struct GeometryOptions {
  bool join = false;  // static meshes into world space, one primitive per material (join.hpp)
  bool quantize = false;
  int position_bits = 14;  // 8–16
  int texcoord_bits = 12;  // 8–16
  MeshCompression compression = MeshCompression::none;

  bool any() const { return join || quantize || compression != MeshCompression::none; }
};

struct Options {
  TextureFormat texture_format = TextureFormat::png;
  ClassOptions colour{.codec = Codec::etc1s};
  ClassOptions data{.codec = Codec::uastc};
  ClassOptions normal{.codec = Codec::uastc};
  Rounding rounding = Rounding::multiple_of_4;
  Filter filter = Filter::box;
  bool mipmaps = true;          // a full chain down to 1×1
  bool keep_alpha_coverage = false;  // MASK materials' levels keep the source's alpha coverage (MipRequest)
  bool png_fallback = false;    // keep the PNG as the texture's core source (the extension then optional)
  bool measure_levels = true;   // each KTX2 level's error as a GPU is given it (LevelError)
  double texel_density = 0;     // texels per scene unit the textures are sized for; 0: their own sizes
  GeometryOptions geometry;
  std::string profile;          // the delivery profile these values started from (presets/delivery/); "": none
  // Not parameters (no stamp records them): where a build keeps encoded textures between runs
  // (OUT/.matbake/encode-cache) and how many bytes at most; an empty folder or 0: none kept.
  std::filesystem::path encode_cache;
  std::uint64_t encode_cache_bytes = 0;

  const ClassOptions& of(TextureClass c) const { return c == TextureClass::colour ? colour : c == TextureClass::data ? data : normal; }
  ClassOptions& of(TextureClass c) { return c == TextureClass::colour ? colour : c == TextureClass::data ? data : normal; }
};

// ---- Sizes -----------------------------------------------------------------------------------------

struct Size {
  int width = 0, height = 0;
  bool operator==(const Size&) const = default;
};

// The size a `source`-sized texture of a class is delivered at: its scale, its max_size on the longer
// side (and `needed`, the longer side the texel density asks for, when set), then rounded; never above
// the source, at least 1×1, aspect kept as closely as the rounding allows.
Size delivered_size(Size source, const ClassOptions& options, Rounding rounding, std::optional<int> needed = {});

// "basisu 1.16.4": the KTX2 encoder a run would use (for build stamps: a new encoder rebuilds the
// KTX2 scenes), or "none: <why>" when there is none.
std::string encoder_identity();

// ---- Texel density: the size the scene needs ------------------------------------------------------

// One triangle as a texture maps it: its area in the scene (world units², every placement counted)
// and in UV space (the texture's [0, 1]² has area 1).
struct MappedTriangle {
  double world_area = 0, uv_area = 0;
};

// The area-weighted share of a texture's triangles that `needed_side` serves: the rest (the smallest
// share of the scene's area, stretched the most) may get fewer texels than asked.
inline constexpr double kDensityPercentile = 0.95;

// The longer side a texture of `source`'s aspect needs so that its triangles get `density` texels
// per scene unit: a triangle of UV area u and world area w mapped on a W × H texture gets
// sqrt(u · W · H / w) texels per unit, so it needs a longer side L = density · sqrt(w / (u · a · b)),
// a = W / L and b = H / L; the result is the kDensityPercentile point of L over the triangles weighted
// by world area, rounded up. None when no triangle has both areas above 0.
std::optional<int> needed_side(const std::vector<MappedTriangle>& triangles, Size source, double density);

// Level k of a full chain: max(1, width >> k) × max(1, height >> k), down to 1×1.
std::vector<Size> mip_sizes(Size base);

// ---- Resampling and mip chains ---------------------------------------------------------------------

// The Kaiser-windowed sinc's weight at distance x (in output texels) from a texel's centre: radius
// 3, β = 4 (what resample uses, and the bench's float64 reference).
double kaiser_weight(double x);

struct Sampling {
  Filter filter = Filter::box;
  Wrap wrap_s = Wrap::repeat, wrap_t = Wrap::repeat;
};

// `in` resampled to `size` per channel on its values as they are (linear light when `in` is decoded
// linear), separably, each output texel from the source texels under the filter scaled to the output's
// texel footprint; reads past an edge follow the wrap modes.
image::Image resample(const image::Image& in, Size size, const Sampling& sampling);

struct MipRequest {
  TextureClass texture_class = TextureClass::colour;
  Sampling sampling;
  std::optional<float> alpha_cutoff;  // a MASK material's: each level's coverage is reported
  bool keep_coverage = false;         // with alpha_cutoff: each resized level keeps the source's coverage
};

// The chain of `source` (decoded linear: colour channels as linear light, alpha and data as stored,
// a normal map's channels as glTF stores them, in [0, 1]) with level 0 at `base`, level 0 first
// (only level 0 unless whole_chain), each level resampled from the source, never from the level
// before. Normal maps: filtered, then renormalised at every level (level 0 included; a zero vector
// becomes +Z). With alpha_cutoff and keep_coverage: each resized level's alpha scaled so that its coverage
// equals the source's as closely as its texel count allows.
std::vector<image::Image> mip_chain(const image::Image& source, Size base, const MipRequest& request,
                                    bool whole_chain = true);
// The same for the levels of `sizes` alone (of a chain whose other levels are made elsewhere).
std::vector<image::Image> mip_levels(const image::Image& source, const std::vector<Size>& sizes, const MipRequest& request);
// The source consumed: a level of its own size is the source itself, not a copy.
std::vector<image::Image> mip_levels(image::Image&& source, const std::vector<Size>& sizes, const MipRequest& request);

// A normal map's texel (x, y, z in [0, 1] as glTF stores them) made unit length, as every level is;
// a zero vector becomes +Z.
void renormalise_normal(float* xyz);

// The fraction of texels whose alpha, stored in 8 bits, is at least `cutoff` (what a MASK material
// renders). 1 when the image has no alpha.
double alpha_coverage(const image::Image& im, float cutoff);

// ---- What a delivery did --------------------------------------------------------------------------

// One level of a delivered KTX2 file as a GPU is given it (basisu transcodes the file to BC7, what
// desktop runtimes pick) against the level matbake made from the source, in the 8-bit codes the
// encoder read (sRGB for colour): docs/delivery.md#level-error.
inline constexpr double kIdenticalPsnr = 99;  // the PSNR reported for a level decoded exactly
struct LevelError {
  double psnr = kIdenticalPsnr;          // dB over the stored channels (RGB, and A when stored)
  double mean_angle = 0, max_angle = 0;  // normal maps: degrees between made and decoded normals
  double coverage = 1;                   // with an alpha cutoff: the decoded level's (what a MASK renders)
  bool operator==(const LevelError&) const = default;
};

struct TextureReport {
  int texture = -1;          // as written
  TextureClass texture_class = TextureClass::colour;
  Codec codec = Codec::png;  // as written (png: kept or resized as PNG/WebP)
  std::string uri;           // the image written; empty when the texture was kept as it was
  Size source, delivered;
  std::optional<int> needed;  // the longer side the texel density asks for, when it was set
  std::vector<int> materials;  // the materials that use the texture
  int levels = 1;
  std::uint64_t source_bytes = 0, bytes = 0;  // the source image's file, the written one
  std::optional<float> alpha_cutoff;         // a MASK material's
  std::vector<double> coverage;              // with alpha_cutoff: the source's, then each level's (8-bit, before encoding)
  std::string note;                          // why it was kept, when it was
  bool reused = false;                       // KTX2: read from the encode cache, not encoded
  bool cache_rejected = false;               // an encode-cache entry under its key failed its content hash: made again
  std::vector<LevelError> level_error;       // KTX2: each level's, level 0 first
  double seconds = 0;                        // decoding and making it (0 when kept or made by another)
};

// ---- Estimates (a plan: docs/inspect.md#estimated-bytes) -----------------------------------------

// What a delivered texture's file is expected to take, without encoding it. PNG: the source's bytes
// scaled by the texel count (exact at its own size). UASTC: 16 bytes a 4 × 4 block of every level,
// exact without zstd; under zstd at most that, and at most kUastcZstdFloorBits more than the
// source file's bits per texel (what the source's own compression found in its texels). ETC1S: half
// the source's bits per texel (kEtc1sSourceShare), at most kEtc1sMaxBits, per texel of level 0 for
// the whole chain. KTX2 files: their header, level index and descriptors more. Fitted on the
// Khronos models; their spread is in docs/inspect.md#estimated-bytes.
inline constexpr double kUastcZstdFloorBits = 0.1;
inline constexpr double kEtc1sSourceShare = 0.5;
inline constexpr double kEtc1sMaxBits = 0.9;
std::uint64_t estimated_bytes(const TextureReport& planned, const ClassOptions& options);

}  // namespace matbake::delivery
