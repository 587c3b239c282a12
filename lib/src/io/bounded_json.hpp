#pragma once
// Outside JSON — glTF text and GLB JSON chunks, stamps, made logs, owner files, kept-map indexes —
// passes one gate before any parser sees it: its size, and its nesting depth counted by one linear
// scan. nlohmann parses iteratively, but what reads the result recurses (tinygltf's value
// conversion, dump(), comparisons): a 40 KB glTF nested 15,000 deep ended every command that read
// it with SIGSEGV, and a kept-map index nested 400,000 deep every later build of its scene.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace matbake {

// Deeper than any file matbake or a glTF exporter writes (a glTF nests about 8 deep, extras
// included), shallow enough for a TBB worker's stack under every recursive reader.
inline constexpr std::size_t kJsonDepthLimit = 256;

// The deepest nesting of arrays and objects in `text`: brackets outside strings (escapes honoured),
// counted in one pass whatever the text holds.
std::size_t json_depth(std::string_view text);

// Why JSON of `size` bytes is not read (over `size_limit`), or empty: checked before it is read.
std::string json_size_problem(std::uint64_t size, std::size_t size_limit);

// Why `text` may not be parsed (over `size_limit` bytes, or nested past kJsonDepthLimit), as the
// end of a sentence about its file; empty when it may be.
std::string json_limit_problem(std::string_view text, std::size_t size_limit);

// `text` parsed when it is within the limits and valid JSON; else a discarded value and `problem`
// says why ("is not valid JSON", or json_limit_problem's words). Json: nlohmann::json or
// nlohmann::ordered_json.
template <class Json>
Json parse_bounded_json(std::string_view text, std::size_t size_limit, std::string& problem) {
  problem = json_limit_problem(text, size_limit);
  if (!problem.empty()) return Json(Json::value_t::discarded);
  Json json = Json::parse(text, nullptr, false);
  if (json.is_discarded()) problem = "is not valid JSON";
  return json;
}

}  // namespace matbake
