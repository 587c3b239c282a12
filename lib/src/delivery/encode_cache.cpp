#include "encode_cache.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <tbb/collaborative_call_once.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>

#include "matbake/atomic_file.hpp"
#include "matbake/image.hpp"
#include "matbake/ktx2.hpp"
#include "../io/unique_fd.hpp"

namespace matbake::delivery {
namespace fs = std::filesystem;
namespace {

// Every version's entries begin with the prefix (so that eviction removes an older version's too);
// only this version's are read.
constexpr std::string_view kEntryPrefix = "matbake encoded texture ";
constexpr std::string_view kMagic = "matbake encoded texture 3\n";
constexpr std::string_view kSuffix = ".ktx2e";
constexpr std::size_t kKeyDigits = 32;
constexpr std::uint32_t kMostLevels = 32;
constexpr std::size_t kLevelErrorValues = 4;  // a LevelError's
constexpr std::size_t kHashBytes = sizeof(XXH128_canonical_t);  // an entry's content hash

using Descriptor = UniqueFd;

bool is_entry_name(const std::string& name) {
  return name.size() == kKeyDigits + kSuffix.size() && name.ends_with(kSuffix) &&
         std::all_of(name.begin(), name.begin() + kKeyDigits, [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

// The most bytes an entry of level 0 at `base` can hold: a KTX2 file as read_output allows the
// encoder, or a PNG or WebP file of 8-bit RGBA stored uncompressed (4 bytes a texel, a filter byte a
// row, chunks), plus the header.
std::uint64_t entry_limit(Size base) {
  return 5 * std::uint64_t(base.width) * std::uint64_t(base.height) + (1u << 20) + kMagic.size() + kHashBytes + 12 + 8 * (kMostLevels + 1) +
         8 * kLevelErrorValues * kMostLevels;
}

template <typename T>
void hash_value(XXH3_state_t* state, const T& value) {
  XXH3_128bits_update(state, &value, sizeof value);
}

void hash_text(XXH3_state_t* state, const std::string& text) {
  hash_value(state, text.size());
  XXH3_128bits_update(state, text.data(), text.size());
}

// An entry's content hash: XXH3-128 of its key and every byte after the hash. An entry is used only
// when it holds: one swapped for another texture's (a valid entry under another key), or with any
// byte changed, was delivered as the texture while its size and levels were right.
XXH128_canonical_t entry_hash(const std::string& key, std::span<const std::string_view> parts) {
  XXH3_state_t* state = XXH3_createState();
  XXH3_128bits_reset(state);
  XXH3_128bits_update(state, key.data(), key.size());
  for (const std::string_view part : parts) XXH3_128bits_update(state, part.data(), part.size());
  XXH128_canonical_t canonical;
  XXH128_canonicalFromHash(&canonical, XXH3_128bits_digest(state));
  XXH3_freeState(state);
  return canonical;
}

// An entry's bytes: the magic, the content hash, the level count, the coverage count, the level
// error count, the coverage values, each level error's four values, the KTX2 file. Here the part
// after the hash up to the file.
std::string header_of(const Encoded& e) {
  std::string h;
  const std::uint32_t counts[3] = {std::uint32_t(e.levels), std::uint32_t(e.coverage.size()), std::uint32_t(e.level_error.size())};
  h.append(reinterpret_cast<const char*>(counts), sizeof counts);
  std::vector<double> values = e.coverage;
  for (const LevelError& l : e.level_error) values.insert(values.end(), {l.psnr, l.mean_angle, l.max_angle, l.coverage});
  if (!values.empty()) h.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
  return h;
}

// The entry in `bytes` when it is one of `key`: its content hash holds, and it is a file of the asked
// size. `rejected` says when an entry of this version was there and failed either.
std::optional<Encoded> parse_entry(const std::vector<unsigned char>& bytes, Size base, const std::string& name, const std::string& key,
                                   bool& rejected) {
  std::uint32_t counts[3];
  constexpr std::size_t kAt = kMagic.size() + kHashBytes;  // where the hashed part begins
  if (bytes.size() < kAt + sizeof counts || std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0) return std::nullopt;
  rejected = true;
  const std::string_view hashed(reinterpret_cast<const char*>(bytes.data()) + kAt, bytes.size() - kAt);
  const XXH128_canonical_t hash = entry_hash(key, std::span(&hashed, 1));
  if (std::memcmp(&hash, bytes.data() + kMagic.size(), kHashBytes) != 0) return std::nullopt;
  std::memcpy(counts, bytes.data() + kAt, sizeof counts);
  if (counts[0] == 0 || counts[0] > kMostLevels || counts[1] > kMostLevels + 1 || counts[2] > counts[0]) return std::nullopt;
  const std::size_t value_count = counts[1] + kLevelErrorValues * counts[2];
  const std::size_t file_at = kAt + sizeof counts + value_count * sizeof(double);
  if (bytes.size() <= file_at) return std::nullopt;
  std::vector<double> values(value_count);
  if (value_count > 0) {  // memcpy to an empty vector's null data() is undefined, even of 0 bytes
    std::memcpy(values.data(), bytes.data() + kAt + sizeof counts, value_count * sizeof(double));
  }
  if (!std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v) && v >= 0; })) return std::nullopt;
  Encoded e;
  e.levels = int(counts[0]);
  e.coverage.assign(values.begin(), values.begin() + counts[1]);
  for (std::size_t at = counts[1]; at < value_count; at += kLevelErrorValues) {
    e.level_error.push_back({values[at], values[at + 1], values[at + 2], values[at + 3]});
  }
  e.file.assign(bytes.begin() + std::ptrdiff_t(file_at), bytes.end());
  if (e.file.size() >= 8 && std::memcmp(e.file.data(), "\xabKTX 20\xbb", 8) == 0) {
    auto read = ktx2::read(e.file, name);
    if (!read || read->width != unsigned(base.width) || read->height != unsigned(base.height) || read->levels.size() != counts[0]) {
      return std::nullopt;
    }
    rejected = false;
    return e;
  }
  // A PNG or WebP file: one level of the asked size whose pixels decode.
  auto layout = image::check_image_bytes(e.file, name);
  if (!layout || counts[0] != 1 || layout->width != base.width || layout->height != base.height) return std::nullopt;
  rejected = false;
  return e;
}

// The entry of `key`, when there is a well-formed one; marked as used now (its modification time,
// which eviction orders by).
std::optional<Encoded> read_entry(const fs::path& folder, const std::string& key, Size base, bool& rejected) {
  const Descriptor dir(::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (dir.fd < 0) return std::nullopt;
  const std::string name = key + std::string(kSuffix);
  const Descriptor file(::openat(dir.fd, name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK));
  struct stat st {};
  if (file.fd < 0 || ::fstat(file.fd, &st) != 0 || !S_ISREG(st.st_mode) || std::uint64_t(st.st_size) > entry_limit(base)) {
    return std::nullopt;
  }
  std::vector<unsigned char> bytes(std::size_t(st.st_size));
  std::size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(file.fd, bytes.data() + got, bytes.size() - got);
    if (n <= 0) return std::nullopt;
    got += std::size_t(n);
  }
  auto entry = parse_entry(bytes, base, (folder / name).string(), key, rejected);
  if (entry) ::futimens(file.fd, nullptr);
  return entry;
}

// Whether the regular file `name` in `dir` begins as an entry does: what eviction may remove.
bool holds_an_entry(int dir, const std::string& name) {
  const Descriptor file(::openat(dir, name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK));
  char head[kEntryPrefix.size()];
  return file.fd >= 0 && ::read(file.fd, head, sizeof head) == ssize_t(sizeof head) && std::string_view(head, sizeof head) == kEntryPrefix;
}

void keep_entry(const EncodeCache& cache, const std::string& key, const Encoded& e) {
  std::error_code ec;
  fs::create_directory(cache.folder, ec);
  if (!fs::is_directory(fs::symlink_status(cache.folder, ec))) return;  // a link or a file: no cache
  const std::string header = header_of(e);
  const std::string_view hashed[2] = {header, std::string_view(reinterpret_cast<const char*>(e.file.data()), e.file.size())};
  const XXH128_canonical_t hash = entry_hash(key, hashed);
  const std::string_view parts[4] = {kMagic, std::string_view(reinterpret_cast<const char*>(&hash), kHashBytes), hashed[0], hashed[1]};
  if (!write_file_atomically(cache.folder / (key + std::string(kSuffix)), parts)) return;  // a full disk: encoded, not kept
  evict_encoded(cache.folder, cache.limit_bytes);
}

// One key encoded once per process: callers of a key share one flag while any of them holds it.
struct InFlight {
  tbb::collaborative_once_flag once;
};

std::shared_ptr<InFlight> in_flight(const std::string& key) {
  static std::mutex lock;
  static std::map<std::string, std::weak_ptr<InFlight>> flights;
  const std::lock_guard<std::mutex> held(lock);
  std::erase_if(flights, [](const auto& f) { return f.second.expired(); });
  std::weak_ptr<InFlight>& slot = flights[key];
  std::shared_ptr<InFlight> flight = slot.lock();
  if (!flight) slot = flight = std::make_shared<InFlight>();
  return flight;
}

}  // namespace

void evict_encoded(const fs::path& folder, std::uint64_t limit) {
  const Descriptor dir(::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (dir.fd < 0) return;
  struct Found {
    std::int64_t used_ns = 0;
    std::uint64_t bytes = 0;
    std::string name;
  };
  std::vector<Found> entries;
  std::uint64_t total = 0;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    struct stat st {};
    if (!is_entry_name(name) || ::fstatat(dir.fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode)) continue;
    entries.push_back({std::int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec, std::uint64_t(st.st_size), name});
    total += std::uint64_t(st.st_size);
  }
  std::sort(entries.begin(), entries.end(), [](const Found& a, const Found& b) { return a.used_ns < b.used_ns; });
  for (const Found& e : entries) {
    if (total <= limit) break;
    if (holds_an_entry(dir.fd, e.name) && ::unlinkat(dir.fd, e.name.c_str(), 0) == 0) total -= e.bytes;
  }
}

Result<std::uint64_t> encode_cache_limit() {
  const char* value = std::getenv("MATBAKE_ENCODE_CACHE_MB");
  if (value == nullptr) return std::uint64_t(1024) << 20;
  const std::string text(value);
  if (text.empty() || text.size() > 9 || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return Error{"MATBAKE_ENCODE_CACHE_MB", "'" + text + "': a whole number of MiB (0 turns the encode cache off)", true};
  }
  return std::uint64_t(std::stoull(text)) << 20;
}

namespace {

using HashState = std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)>;

// A key's hash begun: the format of entries, `writer`, and what the file is made for, `what`.
HashState start_key(const std::string& writer, const std::vector<std::string>& what) {
  HashState state(XXH3_createState(), XXH3_freeState);
  XXH3_128bits_reset(state.get());
  hash_text(state.get(), std::string(kMagic) + writer);
  for (const std::string& w : what) hash_text(state.get(), w);
  return state;
}

// A key finished by what every made file depends on: the source's layout and pixels, the size of
// level 0 and the mip request; 32 hex digits.
std::string finish_key(XXH3_state_t* s, const image::Image& source, Size base, const MipRequest& mips) {
  for (const int v : {source.width, source.height, source.channels, source.alpha_channel, base.width, base.height,
                      int(mips.texture_class), int(mips.sampling.filter), int(mips.sampling.wrap_s), int(mips.sampling.wrap_t),
                      int(mips.alpha_cutoff.has_value()), int(mips.keep_coverage)}) {
    hash_value(s, v);
  }
  hash_value(s, mips.alpha_cutoff.value_or(0.0f));
  for (const std::string& name : source.channel_names) hash_text(s, name);
  XXH3_128bits_update(s, source.pixels.data(), source.pixels.size() * sizeof(float));
  XXH128_canonical_t canonical;
  XXH128_canonicalFromHash(&canonical, XXH3_128bits_digest(s));
  static constexpr char kHex[] = "0123456789abcdef";
  std::string key;
  for (const unsigned char byte : canonical.digest) key += {kHex[byte >> 4], kHex[byte & 15]};
  return key;
}

}  // namespace

std::string encode_key(const image::Image& source, Size base, const MipRequest& mips, const EncodeRequest& request,
                       const std::string& writer) {
  const HashState state = start_key(writer, encoder_arguments(request));
  XXH3_state_t* s = state.get();
  const ClassOptions& o = request.options;
  for (const double v : {double(o.codec), double(o.quality), double(o.uastc_level), o.uastc_rdo, double(o.zstd)}) hash_value(s, v);
  for (const int v : {int(request.texture_class), int(request.mipmaps), int(request.alpha), int(request.measure_levels)}) hash_value(s, v);
  return finish_key(s, source, base, mips);
}

std::string made_file_key(const image::Image& source, Size base, const MipRequest& mips, const std::string& format, int png_level,
                          const std::string& writer) {
  const HashState state = start_key(writer, {format, std::to_string(png_level)});
  return finish_key(state.get(), source, base, mips);
}

Result<Encoded> through_cache(const EncodeCache& cache, const std::string& key, Size base, const std::function<Result<Encoded>()>& encode,
                              bool& reused, bool* rejected) {
  reused = false;
  if (!cache.on()) return encode();
  bool bad = false;
  if (auto hit = read_entry(cache.folder, key, base, bad)) {
    reused = true;
    return std::move(*hit);
  }
  std::optional<Result<Encoded>> made;
  tbb::collaborative_call_once(in_flight(key)->once, [&] {
    if (rejected != nullptr) *rejected = bad;  // this call makes it again (another reads what it made)
    made = encode();
    if (*made) keep_entry(cache, key, **made);
  });
  if (made) return std::move(*made);
  if (auto hit = read_entry(cache.folder, key, base, bad)) {  // another task of this process encoded it
    reused = true;
    return std::move(*hit);
  }
  // It failed there, or was not kept; this call's own inputs are still whole (its function did not run).
  return encode();
}

Result<Encoded> encode_with_cache(const EncodeCache& cache, const Encoder& encoder, image::Image source, Size base,
                                  const MipRequest& mips, const EncodeRequest& request, const std::string& writer, bool& reused,
                                  bool* rejected) {
  const std::string key = cache.on() ? encode_key(source, base, mips, request, writer) : std::string();
  return through_cache(cache, key, base, [&] { return encode_texture(encoder, std::move(source), base, mips, request, writer); }, reused,
                       rejected);
}

}  // namespace matbake::delivery
