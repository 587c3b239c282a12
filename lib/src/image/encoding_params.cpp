#include "matbake/encoding_params.hpp"

namespace matbake::image {
const params::Group<Encoding>& encoding_params() {
  static const params::Group<Encoding> group{{{params::Spec{.name = "png_compression",
                            .kind = params::Kind::integer_or_text,
                            .help = "Deflate effort of 8/16-bit PNG outputs: fast (level 1), default (6), small (12) or "
                                    "a level 0 to 12 (docs/performance.md has size and time per level)",
                            .example = "small"},
               [](Encoding& e, const params::Value& v) -> std::optional<std::string> {
                 std::optional<int> level;
                 if (const auto* n = std::get_if<std::int64_t>(&v)) {
                   if (*n >= 0 && *n <= kPngLevelSmallest) level = int(*n);
                 } else {
                   level = png_level_from_name(std::get<std::string>(v));
                 }
                 if (!level) return "fast, default, small or a level 0 to 12";
                 e.png_level = *level;
                 return std::nullopt;
               },
               [](const Encoding& e) { return nlohmann::json(e.png_level); }}}};
  return group;
}

}  // namespace matbake::image
