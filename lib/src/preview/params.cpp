#include <charconv>

#include "matbake/preview_params.hpp"
#include "matbake/shading_catalog.hpp"

namespace matbake::preview {
namespace {

std::vector<std::string> model_names() {
  std::vector<std::string> names;
  for (const shading::ModelInfo& m : shading::models()) names.emplace_back(m.name);
  return names;
}

// "0.25,0.5,1": one column per value, each a gloss in [0, 1].
params::Param<Options> gloss_sweep() {
  return {params::Spec{.name = "gloss_sweep",
                       .kind = params::Kind::text,
                       .help = "Columns at these gloss values, comma-separated, each 0 to 1 (unset: one column at "
                               "each material's gloss)",
                       .example = "0.25,0.5,1"},
          [](Options& o, const params::Value& v) -> std::optional<std::string> {
            const std::string& text = std::get<std::string>(v);
            std::vector<double> glosses;
            for (std::size_t start = 0; start <= text.size();) {
              const std::size_t comma = std::min(text.find(',', start), text.size());
              double g = -1;
              const auto [end, error] = std::from_chars(text.data() + start, text.data() + comma, g);
              if (error != std::errc() || end != text.data() + comma || !(g >= 0 && g <= 1)) {
                return "gloss values 0 to 1, comma-separated";
              }
              glosses.push_back(g);
              start = comma + 1;
            }
            o.glosses = std::move(glosses);
            return std::nullopt;
          },
          [](const Options& o) -> nlohmann::json {
            if (o.glosses.empty()) return nullptr;
            return o.glosses;
          }};
}

}  // namespace

const params::Group<Options>& options_params() {
  using params::Spec;
  static const params::Group<Options> group{{
      params::text<Options>(Spec{.name = "model",
                                 .help = "BRDF for the direct lights",
                                 .choices = model_names(),
                                 .example = "strauss"},
                            [](auto& o) -> auto& { return o.model; }),
      params::integer<Options>(Spec{.name = "size", .help = "Pixels per cell", .min = 8, .max = 4096, .example = "64"},
                               [](auto& o) -> auto& { return o.cell_size; }),
      gloss_sweep(),
  }};
  return group;
}

}  // namespace matbake::preview
