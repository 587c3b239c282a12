#pragma once
// Encoded textures (KTX2 files, and the PNG or WebP files of resized textures) kept between runs, so
// that a scene rebuilt for another reason (an AO setting, a material that changed one texture)
// encodes only the textures whose pixels or settings changed, and two scenes of one build sharing a
// texture encode it once. A build keeps them in its output folder's
// state (OUT/.matbake/encode-cache/), one file per encode named by its key; least recently used
// entries are removed past a size limit. Entries are outside input: read through O_NOFOLLOW, size-
// limited, checked against their content hash and parsed as a file of the asked size, or ignored
// (encoded again).
#include <cstdint>
#include <filesystem>
#include <functional>

#include "encode.hpp"

namespace matbake::delivery {

// MATBAKE_ENCODE_CACHE_MB when set (0: no cache), else 1024: the most an output folder's encode cache
// holds. An error names the variable when its value is not a whole number of MiB.
Result<std::uint64_t> encode_cache_limit();

struct EncodeCache {
  std::filesystem::path folder;  // empty: no cache
  std::uint64_t limit_bytes = 0;
  bool on() const { return !folder.empty() && limit_bytes > 0; }
};

// Least recently used entries (by modification time: a read marks it) removed from `folder` until its
// entries fit in `limit` bytes. Only regular files named as entries (32 hex digits + ".ktx2e") that
// begin as one (of any version) are removed, by name relative to the folder's descriptor (no link is followed).
void evict_encoded(const std::filesystem::path& folder, std::uint64_t limit);

// The key of an encode: XXH3-128 of everything its bytes depend on — the source's layout and pixels
// (level 0 and every level are made from them), the size of level 0, the mip request, the class's
// codec settings, the encoder's arguments, whether its levels are measured, and `writer` (matbake's
// and basisu's versions).
std::string encode_key(const image::Image& source, Size base, const MipRequest& mips, const EncodeRequest& request,
                       const std::string& writer);

// The key of a PNG or WebP file that delivery makes of `source` (level 0 alone, at `base`): as
// encode_key, with the file's format ("png", "webp") and deflate effort for the encoder's settings.
std::string made_file_key(const image::Image& source, Size base, const MipRequest& mips, const std::string& format, int png_level,
                          const std::string& writer);

// `encode` through the cache under `key`: an entry found (a KTX2 file of level 0 at `base`, or a
// PNG or WebP file of that size) is used and marked recently used, else encode() runs and its result
// is kept. `reused` says which; `rejected` (when given) whether an entry under the key failed its
// content hash or shape (another texture's entry, changed bytes): it is made again and overwritten,
// never delivered. Within a process one key is encoded once: a second caller waits for
// the first (its thread working on other tasks meanwhile) and reads its entry.
Result<Encoded> through_cache(const EncodeCache& cache, const std::string& key, Size base, const std::function<Result<Encoded>()>& encode,
                              bool& reused, bool* rejected = nullptr);

// encode_texture through the cache, under encode_key.
Result<Encoded> encode_with_cache(const EncodeCache& cache, const Encoder& encoder, image::Image source, Size base,
                                  const MipRequest& mips, const EncodeRequest& request, const std::string& writer, bool& reused,
                                  bool* rejected = nullptr);

}  // namespace matbake::delivery
