#include "matbake/join.hpp"
#include "matbake/pack.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <array>
#include <fstream>
#include <sstream>

#include "builtin_layouts.hpp"
#include "matbake/near_names.hpp"
#include "matbake/read_file.hpp"
#include "../io/bounded_json.hpp"

namespace matbake::pack {
namespace fs = std::filesystem;
using material::component_count;
using material::find_source;
using material::Source;
using material::SourceKind;
namespace {


double apply(Transform transform, double x) { return transform == Transform::one_minus ? 1.0 - x : x; }

Result<Channel> parse_channel(const nlohmann::json& j, const std::string& origin, const std::string& where) {
  const auto bad = [&](const std::string& what) { return Error{origin, where + ": " + what}; };
  if (!j.is_object()) return bad("a channel must be an object");
  Channel c;
  for (const auto& [key, value] : j.items()) {
    if (key == "source") {
      if (!value.is_string()) return bad("\"source\" must be a string");
      c.source = value.get<std::string>();
      if (!find_source(c.source)) return bad("unknown source \"" + c.source + "\"");
    } else if (key == "component") {
      if (!value.is_number_integer()) return bad("\"component\" must be 0, 1 or 2");
      c.component = value.get<int>();
    } else if (key == "transform") {
      const std::string t = value.is_string() ? value.get<std::string>() : "";
      if (t == "identity") {
        c.transform = Transform::identity;
      } else if (t == "one_minus") {
        c.transform = Transform::one_minus;
      } else {
        return bad("\"transform\" must be \"identity\" or \"one_minus\"");
      }
    } else if (key == "default" || key == "value") {
      if (!value.is_number()) return bad("\"" + key + "\" must be a number");
      c.fallback = value.get<double>();
    } else {
      return bad("unknown key \"" + key + "\"");
    }
  }
  if (c.source.empty() && !c.fallback) return bad("needs a \"source\" or a \"value\"");
  if (j.contains("value") && !c.source.empty()) return bad("\"value\" is a constant channel: use \"default\" with a source");
  if (!c.source.empty()) {
    const int components = component_count(find_source(c.source)->kind);
    if (c.component < 0 || c.component >= components) {
      return bad("component " + std::to_string(c.component) + " of \"" + c.source + "\", which has " +
                 std::to_string(components));
    }
  }
  return c;
}

Result<Texture> parse_texture(const nlohmann::json& j, const std::string& origin, std::size_t index) {
  const std::string where = "texture " + std::to_string(index);
  if (!j.is_object() || !j.contains("name") || !j["name"].is_string() || !j.contains("channels") ||
      !j["channels"].is_array()) {
    return Error{origin, where + ": needs \"name\" (string) and \"channels\" (array)"};
  }
  Texture t;
  t.name = j["name"].get<std::string>();
  t.color = j.value("color", false);
  const auto& channels = j["channels"];
  if (channels.empty() || channels.size() > 4) return Error{origin, t.name + ": 1 to 4 channels"};
  if (t.color && channels.size() < 3) return Error{origin, t.name + ": a colour texture has RGB (3 or 4 channels)"};
  for (std::size_t i = 0; i < channels.size(); ++i) {
    auto c = parse_channel(channels[i], origin, t.name + " channel " + std::to_string(i));
    if (!c) return c.error();
    t.channels.push_back(std::move(c.value()));
  }
  return t;
}

image::Image blank(int width, int height, int channels) {
  image::Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  static const std::array<std::vector<std::string>, 5> kNames = {
      {{}, {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}}};
  image.channel_names = kNames[std::size_t(channels)];
  image.alpha_channel = channels == 2 ? 1 : channels == 4 ? 3 : -1;
  image::reserve_pixels(image.pixels, image.sample_count());
  image.pixels.assign(image.sample_count(), 0.0f);
  return image;
}

// The file channel a source takes (FileChannels), or -1 for its first `components` as stored.
Result<int> picked_channel(const image::Image& file, SourceKind kind, FileChannels pick, const fs::path& path,
                           std::string_view source) {
  const int colour_channels = file.alpha_channel >= 0 ? file.channels - 1 : file.channels;
  switch (pick) {
    case FileChannels::as_stored: return -1;
    case FileChannels::rgb:
      if (kind == SourceKind::scalar) return Error{path.string(), std::string(source) + " takes one channel, not rgb"};
      if (colour_channels < 3) return Error{path.string(), "has no RGB (" + std::to_string(file.channels) + " channels)"};
      return -1;
    case FileChannels::a:
      if (file.alpha_channel < 0) {
        return Error{path.string(), "has no alpha channel (" + std::to_string(file.channels) + " channels) for " + std::string(source)};
      }
      return file.alpha_channel;
    default: {
      const int index = int(pick) - int(FileChannels::r);
      if (index >= colour_channels) {
        return Error{path.string(), "has no channel " + std::string(name_in(kFileChannelNames, pick)) + " (" +
                                        std::to_string(file.channels) + " channels) for " + std::string(source)};
      }
      return index;
    }
  }
}

// A source as a map: its components from a file's channels (grey → RGB repeats it), or from the
// one channel it picks.
Result<image::Image> source_from_file(const image::Image& file, SourceKind kind, FileChannels pick, const fs::path& path,
                                      std::string_view source) {
  auto picked = picked_channel(file, kind, pick, path, source);
  if (!picked) return picked.error();
  const int components = component_count(kind);
  image::Image map = blank(file.width, file.height, components);
  const bool grey = file.channels < 3;
  const std::size_t texels = std::size_t(file.width) * std::size_t(file.height);
  for (std::size_t i = 0; i < texels; ++i) {
    for (int c = 0; c < components; ++c) {
      const int from = *picked >= 0 ? *picked : grey ? 0 : c;
      map.pixels[i * std::size_t(components) + std::size_t(c)] = file.pixels[i * std::size_t(file.channels) + std::size_t(from)];
    }
  }
  return map;
}

// The normal map as glTF stores it: decoded to vectors (green flipped for DirectX's convention),
// renormalised and stored again (0.5·n + 0.5); refused when it is not a tangent-space normal map.
Status finish_normal_map(material::Maps& maps, NormalConvention convention, const std::string& origin) {
  const auto found = maps.maps.find(material::kNormal);
  if (found == maps.maps.end()) return success();
  std::vector<float>& v = found->second.pixels;
  const std::size_t texels = v.size() / 3;
  std::size_t bad = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    double n[3] = {2.0 * v[3 * i] - 1, 2.0 * v[3 * i + 1] - 1, 2.0 * v[3 * i + 2] - 1};
    if (convention == NormalConvention::directx) n[1] = -n[1];
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    bad += n[2] < 0 || std::abs(length - 1) > kNormalLengthTolerance;
    for (int c = 0; c < 3; ++c) {
      const double unit = length > 1e-6 ? n[c] / length : c == 2 ? 1.0 : 0.0;  // no direction: the surface's
      v[3 * i + std::size_t(c)] = float(0.5 * unit + 0.5);
    }
  }
  if (double(bad) > kNormalBadShare * double(texels)) {
    char share[32];
    std::snprintf(share, sizeof share, "%.3g%%", 100.0 * double(bad) / double(texels));
    return Error{origin, "normal: not a tangent-space normal map: " + std::string(share) +
                             " of its texels point below the surface (z < 0) or are far from unit length (an "
                             "object-space normal map, or a height or colour map?)"};
  }
  return success();
}

Result<std::shared_ptr<const image::Image>> read_shared(const std::filesystem::path& path, color::Transfer decode) {
  auto file = image::read_image(path, decode);
  if (!file) return file.error();
  return std::make_shared<const image::Image>(std::move(*file));
}

// Emission is light given off: an emissive map below 0 has no meaning in any renderer (above 1 is
// HDR emission, which export carries with KHR_materials_emissive_strength).
Status check_emission(const image::Image& map, const SourceInput& input) {
  if (input.name != material::kEmissive) return success();
  const auto lowest = std::min_element(map.pixels.begin(), map.pixels.end());
  if (lowest == map.pixels.end() || *lowest >= 0) return success();
  const std::size_t texel = std::size_t(lowest - map.pixels.begin()) / std::size_t(map.channels);
  return Error{input.file.string(), "emissive values below 0 (" + std::to_string(*lowest) + " at x " +
                                        std::to_string(texel % std::size_t(map.width)) + ", y " +
                                        std::to_string(texel / std::size_t(map.width)) + "): emission cannot be negative"};
}

// How a colour file is decoded: as `decode` says, else by decode_transfer's rule.
Result<color::Transfer> colour_decode(const fs::path& file, const MaterialOptions& options) {
  return options.decode ? Result<color::Transfer>(*options.decode) : decode_transfer(file, options.transfer);
}

}  // namespace

std::vector<std::string> builtin_layout_names() {
  std::vector<std::string> names;
  for (const BuiltinLayout& b : builtin_layouts()) names.emplace_back(b.name);
  return names;
}

constexpr std::size_t kLayoutLimit = 1u << 20;  // a layout names a few textures and channels

Result<Layout> parse_layout(std::string_view json_text, const std::string& origin) {
  return guarded(origin, [&]() -> Result<Layout> {
    nlohmann::json j;
    if (std::string problem = json_limit_problem(json_text, kLayoutLimit); !problem.empty()) return Error{origin, problem};
    try {
      j = nlohmann::json::parse(json_text);
    } catch (const nlohmann::json::parse_error& e) {
      return Error{origin, "not a valid layout (JSON): " + std::string(e.what())};
    }
    if (!j.is_object() || !j.contains("textures") || !j["textures"].is_array() || j["textures"].empty()) {
      return Error{origin, "a layout needs a non-empty \"textures\" array"};
    }
    Layout layout;
    layout.name = j.value("name", fs::path(origin).stem().string());
    layout.description = j.value("description", "");
    for (std::size_t i = 0; i < j["textures"].size(); ++i) {
      auto t = parse_texture(j["textures"][i], origin, i);
      if (!t) return t.error();
      layout.textures.push_back(std::move(t.value()));
    }
    return layout;
  });
}

Result<ResolvedLayout> resolve_layout(const std::string& reference, const fs::path& folder) {
  // The presets parsed once (a manifest of 10,000 materials names one 10,000 times).
  static const std::map<std::string_view, Result<Layout>> parsed_presets = [] {
    std::map<std::string_view, Result<Layout>> parsed;
    for (const BuiltinLayout& b : builtin_layouts()) {
      parsed.emplace(b.name, parse_layout(b.json, "presets/layouts/" + std::string(b.name) + ".json"));
    }
    return parsed;
  }();
  if (const auto preset = parsed_presets.find(reference); preset != parsed_presets.end()) {
    if (!preset->second) return preset->second.error();
    return ResolvedLayout{*preset->second, {}};
  }
  fs::path file = (folder / reference).lexically_normal();
  if (!file.has_extension()) file += ".json";
  std::error_code ec;
  if (reference.empty() || !fs::is_regular_file(file, ec)) {
    const std::vector<std::string> presets = builtin_layout_names();
    return Error{"", "layout '" + reference + "': no preset of that name (presets: " + join(presets, ", ") +
                         did_you_mean(reference, presets) + ") and no layout file " + file.string(), true};
  }
  std::string text;
  if (!read_whole_file(file, text)) return Error{file.string(), "cannot read the layout file"};
  auto layout = parse_layout(text, file.string());
  if (!layout) return layout.error();
  return ResolvedLayout{std::move(*layout), file};
}

Result<SourceInput> source_from_text(std::string_view name, const std::string& text, const fs::path& folder) {
  SourceInput input{std::string(name), {}, {}, FileChannels::as_stored};
  std::vector<double> numbers;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string part = text.substr(start, comma - start);
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || std::isspace(static_cast<unsigned char>(part[0]))) {
      numbers.clear();
      break;
    }
    numbers.push_back(v);
    start = comma + 1;
  }
  if (numbers.empty()) {
    if (text.empty()) return Error{"", "a file name or 1 or 3 numbers expected", true};
    const std::size_t colon = text.rfind(':');
    const std::string suffix = colon == std::string::npos ? "" : text.substr(colon + 1);
    const auto channels = value_in(kFileChannelNames, suffix);
    // "file.png:y": a channel suffix that names no channel, said now rather than as a missing file.
    if (!channels && colon > 0 && !suffix.empty() && suffix.size() <= 3 && suffix.find_first_of("./\\") == std::string::npos &&
        !fs::exists(folder / text)) {
      return Error{"", "'" + text + "': channel '" + suffix + "' is not " + names_in(kFileChannelNames), true};
    }
    if (channels && colon > 0) input.channels = *channels;
    input.file = folder / (channels && colon > 0 ? text.substr(0, colon) : text);
    return input;
  }
  if (numbers.size() != 1 && numbers.size() != 3) {
    return Error{"", "'" + text + "': 1 or 3 numbers expected, got " + std::to_string(numbers.size()), true};
  }
  for (double v : numbers) {
    if (!material::is_valid_constant(v)) return Error{"", "'" + text + "': values are in [0, 1]", true};
  }
  input.constant = std::move(numbers);
  return input;
}

Result<Layout> find_layout(const std::string& name_or_path) {
  auto resolved = resolve_layout(name_or_path, {});
  if (!resolved) return resolved.error();
  return std::move(resolved->layout);
}

Result<color::Transfer> decode_transfer(const fs::path& path, color::Transfer authored) {
  auto info = image::probe_image(path);
  if (!info) return info.error();
  if (info->tagged) return *info->tagged;
  return info->stored_type == image::SampleType::u8 ? authored : color::Transfer::linear;
}

std::vector<std::string> decode_overrides(const std::vector<SourceInput>& inputs, const MaterialOptions& options) {
  std::vector<std::string> notes;
  if (!options.decode) return notes;
  for (const SourceInput& input : inputs) {
    const Source* source = find_source(input.name);
    if (input.file.empty() || !source || source->kind != SourceKind::color) continue;
    auto info = image::probe_image(input.file);
    if (!info || !info->tagged || *info->tagged == *options.decode) continue;
    notes.push_back(input.file.string() + ": decoded as " + std::string(color::transfer_name(*options.decode)) +
                    " as asked, though its " + info->tag + " says " + std::string(color::transfer_name(*info->tagged)));
  }
  return notes;
}

Result<material::Maps> load_sources(const std::vector<SourceInput>& inputs, const MaterialOptions& options,
                                    const ImageReader& read) {
  return guarded("", [&]() -> Result<material::Maps> {
    material::Maps result;
    std::map<std::string, std::string> origin;  // source → file, for size errors
    for (const SourceInput& input : inputs) {
      const Source* source = find_source(input.name);
      if (!source) return Error{"", "unknown source \"" + input.name + "\"", true};
      if (input.file.empty()) continue;
      color::Transfer decode = color::Transfer::linear;
      if (source->kind == SourceKind::color) {
        auto t = colour_decode(input.file, options);
        if (!t) return t.error();
        decode = *t;
      }
      auto file = read ? read(input.file, decode) : read_shared(input.file, decode);
      if (!file) return file.error();
      auto map = source_from_file(**file, source->kind, input.channels, input.file, input.name);
      if (!map) return map.error();
      if (Status s = check_emission(*map, input); !s) return s.error();
      result.maps[input.name] = std::move(*map);
      origin[input.name] = input.file.string();
    }
    // One size for all: the largest by pixel count, the others resized to it or refused.
    const image::Image* largest = nullptr;
    for (const auto& [name, map] : result.maps) {
      if (!largest || std::size_t(map.width) * map.height > std::size_t(largest->width) * largest->height) largest = &map;
    }
    if (largest) {
      result.width = largest->width;
      result.height = largest->height;
      for (auto& [name, map] : result.maps) {
        if (map.width == result.width && map.height == result.height) continue;
        if (!options.resize) {
          const auto& first = *std::find_if(result.maps.begin(), result.maps.end(), [&](const auto& m) {
            return m.second.width == result.width && m.second.height == result.height;
          });
          return Error{origin[name], std::to_string(map.width) + "x" + std::to_string(map.height) + ", but " +
                                         origin[first.first] + " is " + std::to_string(result.width) + "x" +
                                         std::to_string(result.height) + " (resizing resamples to the largest)"};
        }
        map = image::resize_image(map, result.width, result.height);
      }
    } else {
      result.width = options.width > 0 ? options.width : 1;
      result.height = options.height > 0 ? options.height : 1;
      if (Status s = image::check_image_size("", result.width, result.height); !s) return s.error();
    }
    for (const SourceInput& input : inputs) {
      if (!input.file.empty()) continue;
      const Source* source = find_source(input.name);
      const int components = component_count(source->kind);
      const std::size_t n = input.constant.size();
      if (!(n == 1 || (n == 3 && source->kind != SourceKind::scalar))) {
        return Error{"", input.name + ": " + (source->kind != SourceKind::scalar ? "1 or 3 values" : "one value") +
                             " expected, got " + std::to_string(n), true};
      }
      image::Image map = blank(result.width, result.height, components);
      for (std::size_t i = 0; i < map.pixels.size(); ++i) {
        map.pixels[i] = float(input.constant[n == 1 ? 0 : i % std::size_t(components)]);
      }
      result.maps[input.name] = std::move(map);
    }
    if (Status s = finish_normal_map(result, options.normal_y, origin[std::string(material::kNormal)]); !s) return s.error();
    return result;
  });
}

Result<material::Maps> read_packed(const Layout& layout, const std::vector<std::filesystem::path>& files,
                                   const MaterialOptions& options, const ImageReader& read) {
  return guarded("", [&]() -> Result<material::Maps> {
    if (files.size() != layout.textures.size()) {
      return Error{"", "layout " + layout.name + " takes " + std::to_string(layout.textures.size()) + " textures, got " +
                           std::to_string(files.size()), true};
    }
    std::vector<image::Image> textures;
    std::vector<std::string> paths;
    for (std::size_t t = 0; t < files.size(); ++t) {
      color::Transfer decode = color::Transfer::linear;
      if (layout.textures[t].color) {
        auto d = colour_decode(files[t], options);
        if (!d) return d.error();
        decode = *d;
      }
      auto image = read ? read(files[t], decode) : read_shared(files[t], decode);
      if (!image) return image.error();
      textures.push_back(**image);
      paths.push_back(files[t].string());
    }
    auto maps = unpack(layout, textures, paths);
    if (!maps) return maps.error();
    std::string normal_file;
    for (std::size_t t = 0; t < files.size(); ++t) {
      for (const Channel& c : layout.textures[t].channels) {
        if (c.source == material::kNormal) normal_file = files[t].string();
      }
    }
    if (Status s = finish_normal_map(*maps, options.normal_y, normal_file); !s) return s.error();
    return maps;
  });
}

Result<material::Maps> load_material(const std::vector<SourceInput>& sources, const Layout* packed,
                                     const std::vector<fs::path>& packed_files, const MaterialOptions& options,
                                     const ImageReader& read) {
  if (!packed) return load_sources(sources, options, read);
  auto maps = read_packed(*packed, packed_files, options, read);
  if (!maps || sources.empty()) return maps;
  MaterialOptions sized = options;
  sized.width = maps->width, sized.height = maps->height;
  auto overrides = load_sources(sources, sized, read);
  if (!overrides) return overrides.error();
  if (overrides->width != maps->width || overrides->height != maps->height) {
    if (!options.resize) {
      return Error{packed_files.front().string(), std::to_string(maps->width) + "x" + std::to_string(maps->height) +
                                                      ", but the sources given with it are " +
                                                      std::to_string(overrides->width) + "x" +
                                                      std::to_string(overrides->height) + " (resizing resamples them)"};
    }
    for (auto& [name, map] : overrides->maps) map = image::resize_image(map, maps->width, maps->height);
  }
  for (auto& [name, map] : overrides->maps) maps->maps[name] = std::move(map);
  return maps;
}

std::vector<std::string> layout_sources(const Layout& layout) {
  std::vector<std::string> names;
  for (const Texture& t : layout.textures) {
    for (const Channel& c : t.channels) {
      if (!c.source.empty() && std::find(names.begin(), names.end(), c.source) == names.end()) names.push_back(c.source);
    }
  }
  return names;
}

bool texture_written(const Texture& texture, const material::MapNames& given) {
  bool reads = false;
  for (const Channel& c : texture.channels) {
    if (c.source.empty()) continue;
    if (given.contains(c.source)) return true;
    reads = true;
  }
  return !reads;
}

namespace {

// A channel with no default needs its map, whether or not the texture is written.
Status check_required(const Layout& layout, const Texture& t, const material::Maps& sources) {
  for (const Channel& channel : t.channels) {
    if (!channel.fallback && (channel.source.empty() || !sources.find(channel.source))) {
      return Error{"", "layout " + layout.name + " needs " + channel.source, true};
    }
  }
  return success();
}

// One of the layout's textures, made from the maps.
Result<image::Image> pack_texture(const Layout& layout, const Texture& t, const material::Maps& sources) {
  if (Status s = check_required(layout, t, sources); !s) return s.error();
  image::Image out = blank(sources.width, sources.height, int(t.channels.size()));
  const std::size_t texels = std::size_t(out.width) * std::size_t(out.height), stride = t.channels.size();
  for (std::size_t c = 0; c < stride; ++c) {
    const Channel& channel = t.channels[c];
    const image::Image* map = channel.source.empty() ? nullptr : sources.find(channel.source);
    for (std::size_t i = 0; i < texels; ++i) {
      const double x = map ? map->pixels[i * std::size_t(map->channels) + std::size_t(channel.component)]
                           : *channel.fallback;
      out.pixels[i * stride + c] = float(apply(channel.transform, x));
    }
  }
  return out;
}

}  // namespace

Result<std::vector<image::Image>> pack(const Layout& layout, const material::Maps& sources) {
  return guarded("", [&]() -> Result<std::vector<image::Image>> {
    std::vector<image::Image> textures;
    for (const Texture& t : layout.textures) {
      auto texture = pack_texture(layout, t, sources);
      if (!texture) return texture.error();
      textures.push_back(std::move(*texture));
    }
    return textures;
  });
}

Result<material::Maps> unpack(const Layout& layout, std::span<const image::Image> textures,
                          std::span<const std::string> texture_paths) {
  return guarded("", [&]() -> Result<material::Maps> {
    if (textures.size() != layout.textures.size()) {
      return Error{"", "layout " + layout.name + " has " + std::to_string(layout.textures.size()) + " textures, got " +
                           std::to_string(textures.size()), true};
    }
    material::Maps result;
    result.width = textures[0].width;
    result.height = textures[0].height;
    for (std::size_t t = 0; t < textures.size(); ++t) {
      const image::Image& in = textures[t];
      const Texture& spec = layout.textures[t];
      if (in.width != result.width || in.height != result.height) {
        return Error{texture_paths[t], std::to_string(in.width) + "x" + std::to_string(in.height) + ", but " +
                                           texture_paths[0] + " is " + std::to_string(result.width) + "x" +
                                           std::to_string(result.height)};
      }
      // A file with fewer channels than the texture (an RGB diffuse for Schüler's RGB + mask) is
      // read when each missing channel has a default: the source takes that default.
      for (std::size_t c = std::size_t(in.channels); c < spec.channels.size(); ++c) {
        if (!spec.channels[c].fallback) {
          return Error{texture_paths[t], std::to_string(in.channels) + " channels; layout " + layout.name + " texture " +
                                             spec.name + " has " + std::to_string(spec.channels.size()) + " and channel " +
                                             std::to_string(c) + " (" + spec.channels[c].source + ") has no default"};
        }
      }
      const std::size_t texels = std::size_t(in.width) * std::size_t(in.height);
      for (std::size_t c = 0; c < spec.channels.size(); ++c) {
        const Channel& channel = spec.channels[c];
        if (channel.source.empty()) continue;
        const SourceKind kind = find_source(channel.source)->kind;
        auto [it, inserted] = result.maps.try_emplace(channel.source);
        if (inserted) it->second = blank(in.width, in.height, component_count(kind));
        image::Image& map = it->second;
        const bool stored = c < std::size_t(in.channels);
        for (std::size_t i = 0; i < texels; ++i) {
          map.pixels[i * std::size_t(map.channels) + std::size_t(channel.component)] =
              stored ? float(apply(channel.transform, in.pixels[i * std::size_t(in.channels) + c])) : float(*channel.fallback);
        }
      }
    }
    return result;
  });
}

image::WriteOptions write_options(bool color, const OutputOptions& options) {
  image::WriteOptions w;
  w.type = options.type;
  w.colour = color && options.type == image::SampleType::u8 ? options.transfer : color::Transfer::linear;
  w.png_level = options.encoding.png_level;
  return w;
}

Result<std::vector<fs::path>> output_paths(const Layout& layout, const std::vector<std::string>& outputs) {
  std::vector<fs::path> paths;
  if (outputs.size() == 1 && outputs[0].find("{texture}") != std::string::npos) {
    for (const Texture& t : layout.textures) {
      std::string p = outputs[0];
      p.replace(p.find("{texture}"), 9, t.name);
      paths.emplace_back(p);
    }
    return paths;
  }
  if (outputs.size() == layout.textures.size()) return std::vector<fs::path>(outputs.begin(), outputs.end());
  std::vector<std::string> names;
  for (const Texture& t : layout.textures) names.push_back(t.name);
  return Error{"", "layout " + layout.name + " writes " + std::to_string(layout.textures.size()) + " textures (" + join(names, ", ") +
                       "): give as many outputs, or one path with {texture}", true};
}

image::SampleType default_sample_type(const fs::path& path) {
  return path.extension() == ".exr" ? image::SampleType::half : image::SampleType::u8;
}

// 8 and 16-bit files hold [0, 1]: a texture with values outside it (HDR emission from an EXR
// source) is refused rather than clipped. Float rounding of a conversion stays within the slack.
Status check_storable_range(const image::Image& texture, const Texture& spec, const fs::path& path, image::SampleType type) {
  constexpr float kSlack = 1e-5f;
  if (!image::is_integer(type)) return success();
  const auto [low, high] = std::minmax_element(texture.pixels.begin(), texture.pixels.end());
  if (low == texture.pixels.end() || (*low >= -kSlack && *high <= 1 + kSlack)) return success();
  const float worst = *high > 1 + kSlack ? *high : *low;
  const std::size_t at = std::size_t((*high > 1 + kSlack ? high : low) - texture.pixels.begin());
  const Channel& channel = spec.channels[at % spec.channels.size()];
  return Error{path.string(), "texture " + spec.name + " holds " + std::to_string(worst) + " (from " +
                                  (channel.source.empty() ? "a constant" : channel.source) +
                                  "), outside the [0, 1] an " + std::string(image::sample_type_name(type)) +
                                  "-bit file stores: write it as half or float (EXR), or scale the source"};
}

Result<std::vector<fs::path>> write_textures(const Layout& layout, const material::Maps& sources, const WriteRequest& request) {
  return guarded("", [&]() -> Result<std::vector<fs::path>> {
    auto paths = output_paths(layout, request.outputs);
    if (!paths) return paths.error();
    std::vector<NamedOutput> outputs;
    for (std::size_t i = 0; i < paths->size(); ++i) outputs.push_back({(*paths)[i], "texture " + layout.textures[i].name});
    outputs.insert(outputs.end(), request.also.begin(), request.also.end());
    if (Status s = check_outputs(outputs, request.inputs); !s) return s.error();
    // Which textures, as what: only those written are made, every one checked before the first
    // is written.
    const material::MapNames given = sources.names();
    struct Planned {
      std::size_t index;
      image::SampleType type;
      image::Image image;
    };
    std::vector<Planned> planned;
    for (std::size_t t = 0; t < paths->size(); ++t) {
      if (Status s = check_required(layout, layout.textures[t], sources); !s) return s.error();
      if (!texture_written(layout.textures[t], given)) continue;
      auto image = pack_texture(layout, layout.textures[t], sources);
      if (!image) return image.error();
      const image::SampleType type = request.type.value_or(default_sample_type((*paths)[t]));
      if (Status s = check_storable_range(*image, layout.textures[t], (*paths)[t], type); !s) return s.error();
      planned.push_back({t, type, std::move(*image)});
    }
    std::vector<fs::path> written;
    for (const Planned& p : planned) {
      const image::WriteOptions options = write_options(layout.textures[p.index].color, {p.type, request.transfer, request.encoding});
      if (Status s = image::write_image(p.image, (*paths)[p.index], options); !s) return s.error();
      written.push_back((*paths)[p.index]);
    }
    return written;
  });
}

Result<std::vector<fs::path>> write_maps(const material::Maps& maps, const UnpackRequest& request) {
  return guarded(request.folder.string(), [&]() -> Result<std::vector<fs::path>> {
    std::vector<NamedOutput> outputs;
    for (const auto& [name, map] : maps.maps) outputs.push_back({request.folder / (name + "." + request.format), name});
    if (Status s = check_outputs(outputs, request.inputs); !s) return s.error();
    std::vector<fs::path> written;
    for (const NamedOutput& out : outputs) {
      const bool colour = material::find_source(out.role)->kind == material::SourceKind::color;
      const image::SampleType type = request.type.value_or(default_sample_type(out.path));
      if (Status s = image::write_image(maps.maps.at(out.role), out.path, write_options(colour, {type, request.transfer, request.encoding})); !s) {
        return s.error();
      }
      written.push_back(out.path);
    }
    return written;
  });
}

}  // namespace matbake::pack
