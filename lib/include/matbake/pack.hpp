#pragma once
// Packing source maps (diffuse colour, gloss, roughness, ...) into the textures a renderer samples,
// and back. What goes where is data: a layout (presets/layouts/*.json, or a user's file) lists
// each output texture's channels, each taken from a source map's component, optionally as 1 − x.
// docs/pack.md has the format and the presets.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "matbake/enum_names.hpp"
#include "matbake/image.hpp"
#include "matbake/material.hpp"
#include "matbake/output_check.hpp"
#include "matbake/result.hpp"
#include "matbake/workflow.hpp"

namespace matbake::pack {

enum class Transform { identity, one_minus };

struct Channel {
  std::string source;              // empty: the constant `fallback`
  int component = 0;               // 0–2 of a colour source; 0 for a scalar one
  Transform transform = Transform::identity;
  std::optional<double> fallback;  // used when the source is not given (a constant when source is empty)
};

struct Texture {
  std::string name;
  bool color = false;  // channels 0–2 are colour (encoded with the output transfer); others linear
  std::vector<Channel> channels;  // 1 to 4; the fourth is alpha (unassociated)
};

struct Layout {
  std::string name;
  std::string description;
  std::vector<Texture> textures;
};

// The presets compiled into the library (from presets/layouts/), by name.
std::vector<std::string> builtin_layout_names();
// A layout reference, as the command line and the manifest take it: a preset's name, or else a
// layout file `folder`/reference, with ".json" added when it has no extension ("layouts/mine" and
// "layouts/mine.json" are one file). `file` is empty for a preset.
struct ResolvedLayout {
  Layout layout;
  std::filesystem::path file;
};
Result<ResolvedLayout> resolve_layout(const std::string& reference, const std::filesystem::path& folder);
// resolve_layout from the current folder.
Result<Layout> find_layout(const std::string& name_or_path);
Result<Layout> parse_layout(std::string_view json_text, const std::string& origin);

// Which of a file's channels a source takes. as_stored: a colour source its RGB (a grey file
// repeated), a scalar one the first channel; r, g, b or a: that one channel (repeated for a colour
// source); rgb: the three colour channels (colour sources only).
enum class FileChannels { as_stored, r, g, b, a, rgb };
inline constexpr NameTable<FileChannels, 5> kFileChannelNames{
    {{FileChannels::r, "r"}, {FileChannels::g, "g"}, {FileChannels::b, "b"}, {FileChannels::a, "a"}, {FileChannels::rgb, "rgb"}}};

struct SourceInput {
  std::string name;             // a material::sources() name
  std::filesystem::path file;   // an image, or
  std::vector<double> constant; // linear values: 1 (scalar, or grey) or 3 (colour)
  FileChannels channels = FileChannels::as_stored;  // of `file`
};

// A source as text, the one rule of both doors: one number or three ("0.5", "0.9,0.6,0.2") are a
// constant (linear, in [0, 1]), anything else a file relative to `folder` (write "./0.5" for a file
// of that name), ending in ":r", ":g", ":b", ":a" or ":rgb" to take those channels of it
// ("sg.png:a"). Errors say what is wrong with the text, not where it came from.
Result<SourceInput> source_from_text(std::string_view name, const std::string& text, const std::filesystem::path& folder);

// Decodes a file (read_image, or a cache in front of it that decodes each file once).
using ImageReader = std::function<Result<std::shared_ptr<const image::Image>>(const std::filesystem::path&, color::Transfer)>;

// How a material's sources are read, converted and its textures written, whichever door asks
// (pack, unpack, workflow, validate, preview, a manifest's material). Its parameters are described
// once in pack::material_params() (material_params.hpp).
// Which way a normal map's green channel points: OpenGL's +Y (glTF's, Blender's) or DirectX's −Y
// (Unreal's, 3ds Max's), flipped when read so that every map in memory is glTF's.
enum class NormalConvention { opengl, directx };
inline constexpr NameTable<NormalConvention, 2> kNormalConventionNames{
    {{NormalConvention::opengl, "opengl"}, {NormalConvention::directx, "directx"}}};

// A tangent-space normal map is refused when more than this share of its texels point below the
// surface (z < 0) or are further than kNormalLengthTolerance from unit length before renormalising
// (8-bit storage is within 0.01, block compression within about 0.05).
inline constexpr double kNormalBadShare = 0.01;
inline constexpr double kNormalLengthTolerance = 0.25;

struct MaterialOptions {
  color::Transfer transfer = color::Transfer::srgb;  // 8-bit colour: how sources were authored, how outputs are encoded
  std::optional<color::Transfer> decode;             // every colour file, overriding the rule below
  bool resize = false;  // else sources of different sizes are an error
  int width = 0;        // size when every source is a constant (0: 1×1)
  int height = 0;
  std::optional<image::SampleType> bits;  // of written textures; unset: default_sample_type of each path
  std::string format = "png";             // extension of outputs that no path names (a manifest's, unpack's)
  workflow::RoughnessMapping mapping = workflow::kDefaultRoughnessMapping;  // gloss ⇄ roughness of a conversion
  NormalConvention normal_y = NormalConvention::opengl;  // of normal map sources
};
Result<material::Maps> load_sources(const std::vector<SourceInput>& inputs, const MaterialOptions& options,
                                    const ImageReader& read = {});

// A normal map source is decoded to vectors (green flipped for DirectX's convention), checked
// (kNormalBadShare), renormalised and held as glTF stores it, by load_sources and read_packed alike.
// The source maps held by `files`, the textures of `layout` in order: colour textures decoded with
// `options.decode` when given, else as decode_transfer() says; the others linear.
Result<material::Maps> read_packed(const Layout& layout, const std::vector<std::filesystem::path>& files,
                                   const MaterialOptions& options, const ImageReader& read = {});

// A material's maps as both doors give them: the textures of the `packed` layout (when not null)
// unpacked, then each of `sources` in place of the map of its name (`--from schuler A B --gloss 0.5`,
// or a manifest's `packed` with `sources`). Constants take the packed size; a file of another
// size is resized to it with `options.resize`, else refused.
Result<material::Maps> load_material(const std::vector<SourceInput>& sources, const Layout* packed,
                                     const std::vector<std::filesystem::path>& packed_files,
                                     const MaterialOptions& options, const ImageReader& read = {});

// The sources a layout reads, and which of them it cannot do without (no fallback).
std::vector<std::string> layout_sources(const Layout& layout);
// Whether a texture is written for a material with maps of these names: not when it reads maps
// and the material has none of them (gltf-pbr's emissive texture of a material without emission
// would be all default values); a texture of constants only is.
bool texture_written(const Texture& texture, const material::MapNames& given);
Result<std::vector<image::Image>> pack(const Layout& layout, const material::Maps& sources);
// The inverse: source maps from decoded textures (one per layout texture, same size).
Result<material::Maps> unpack(const Layout& layout, std::span<const image::Image> textures,
                          std::span<const std::string> texture_paths);

struct OutputOptions {
  image::SampleType type = image::SampleType::u8;
  color::Transfer transfer = color::Transfer::srgb;  // for colour channels of 8-bit output; else linear
  image::Encoding encoding;
};
image::WriteOptions write_options(bool color, const OutputOptions& options);
// Where a layout's textures go: one path per texture, in order, or one path holding "{texture}"
// (replaced by each texture's name).
Result<std::vector<std::filesystem::path>> output_paths(const Layout& layout, const std::vector<std::string>& outputs);
// The sample type when none is asked: half for .exr, 8-bit for the rest.
image::SampleType default_sample_type(const std::filesystem::path& path);

struct WriteRequest {
  std::vector<std::string> outputs;        // as output_paths takes them
  std::optional<image::SampleType> type;   // unset: default_sample_type of each path
  color::Transfer transfer = color::Transfer::srgb;  // colour channels of 8-bit outputs
  std::vector<std::filesystem::path> inputs;         // files the maps were read from: never written over
  std::vector<NamedOutput> also;                     // the run's other outputs (a report): checked with the textures
  image::Encoding encoding;
};
// Packs `sources` into the layout's textures and writes those texture_written() keeps (each
// atomically), returning their paths. An output that is an input, or two outputs that are one
// file, are refused before anything is written.
Result<std::vector<std::filesystem::path>> write_textures(const Layout& layout, const material::Maps& sources,
                                                          const WriteRequest& request);

// `matbake unpack`'s writing: each source map as <folder>/<source name>.<format> ("kd.png"), the
// folder made when missing; an output that is an input is refused before anything is written.
struct UnpackRequest {
  std::filesystem::path folder;
  std::string format = "png";               // the extension, without its dot
  std::optional<image::SampleType> type;    // unset: default_sample_type of the format
  color::Transfer transfer = color::Transfer::srgb;
  std::vector<std::filesystem::path> inputs;
  image::Encoding encoding;
};
Result<std::vector<std::filesystem::path>> write_maps(const material::Maps& maps, const UnpackRequest& request);

// How to decode a file holding colour when `decode` does not say: as the file's own tag says
// (image::ReadInfo::tagged: PNG cICP/iCCP/sRGB/gAMA, EXR, TIFF), else by its depth: `authored`
// for 8-bit files, linear for 16-bit and float ones (the rule write_options follows).
Result<color::Transfer> decode_transfer(const std::filesystem::path& path, color::Transfer authored);
// The colour sources whose tag disagrees with an explicit `options.decode`, one note each naming
// the file (decode wins; the note says so).
std::vector<std::string> decode_overrides(const std::vector<SourceInput>& inputs, const MaterialOptions& options);

}  // namespace matbake::pack
