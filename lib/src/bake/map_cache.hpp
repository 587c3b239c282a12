#pragma once
// Maps kept from an earlier bake, so that a bake asked again with some parameters changed traces
// only the maps those parameters decide (a build's AO samples: only ao, bent_normal and thickness).
// Each map is kept as its raw floats, one file per texture target, under a key: the content of the
// inputs as read before the bake, the texture targets, and the parameters that map reads
// (map_parameters). The index records each file's size and content hash: a file that differs (a
// tampered or half-written folder) is baked again, never trusted. Nothing read from the folder is
// used as a path.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "matbake/bake.hpp"
#include "matbake/bake_file.hpp"

namespace matbake::bake {

// The parameters `map` reads, by the names bake's flags use: the cage, the texture and its
// anti-aliasing always; green for normal and bent_normal; the AO estimator for ao, bent_normal and
// thickness; matbake's version. No map: the trace's (what every map reads).
nlohmann::json map_parameters(std::optional<Map> map, const Request& request);

// A content hash of `files` (in order), read before they are loaded; an error names an unreadable one.
Result<std::string> inputs_hash(std::span<const std::filesystem::path> files);

// The key of `map` (none: the trace's) in a bake of `targets` (their materials and UV sets, as text)
// from inputs of `inputs_hash`.
std::string map_key(const std::string& inputs_hash, std::optional<Map> map, const Request& request, const std::string& targets);

struct KeptMap {
  std::vector<MapImage> images;  // one per target
};

// What the folder keeps of `map` under `key`, each target's image of `width` × `height`; nothing when
// absent, kept under another key, or any file not as recorded.
std::optional<KeptMap> load_map(const std::filesystem::path& folder, Map map, const std::string& key,
                                std::size_t targets, int width, int height);

// The trace kept under `key`: its boxes and per target its counts (texels, rays, misses, starts
// inside, ...), without maps; nothing when absent or not as recorded.
std::optional<Bake> load_trace(const std::filesystem::path& folder, const std::string& key, std::size_t targets);

// Keeps each of `bake`'s maps named in `keys` (their targets' images) under its key, and the
// trace's counts and boxes under `trace_key`; the index is written before (without those maps) and after.
Status store_maps(const std::filesystem::path& folder, const Bake& bake, const std::string& trace_key,
                  const std::vector<std::pair<Map, std::string>>& keys);

// The files store_maps writes for `maps` over `targets` targets (for the output check).
std::vector<std::filesystem::path> kept_files(const std::filesystem::path& folder, std::span<const Map> maps,
                                              std::size_t targets);

}  // namespace matbake::bake
