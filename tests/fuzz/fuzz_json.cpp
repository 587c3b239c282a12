// The one bounded reader of outside JSON (io/bounded_json.hpp), for every JSON matbake reads: glTF
// text and GLB chunks, stamps, made logs, owner files, kept-map indexes. The depth scan must agree
// with what the parser builds (a value it lets through is no deeper than the limit, and its
// written form has the depth the scan counted), and nothing may crash or recurse past the limit:
// the parsed value is copied, compared and written, as the readers after it do.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include <nlohmann/json.hpp>

#include "lib/src/io/bounded_json.hpp"

using namespace matbake;

namespace {

template <class Json>
void check(std::string_view text) {
  std::string problem;
  const Json parsed = parse_bounded_json<Json>(text, 1 << 20, problem);
  if (!problem.empty()) {
    if (!parsed.is_discarded()) std::abort();
    return;
  }
  if (json_depth(text) > kJsonDepthLimit) std::abort();  // let through past the limit
  // nlohmann stops reading at a NUL byte (what follows is not parsed; the scan still counts it,
  // which can only refuse more): the written form has the depth of what was read.
  const std::size_t depth = json_depth(text.substr(0, text.find('\0')));
  const Json copy = parsed;
  if (!(copy == parsed)) std::abort();
  const std::string written = parsed.dump(-1, ' ', false, Json::error_handler_t::replace);
  if (json_depth(written) != depth) std::abort();  // the scan miscounted (a bracket in a string, an escape)
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  check<nlohmann::json>(text);
  check<nlohmann::ordered_json>(text);
  return 0;
}
