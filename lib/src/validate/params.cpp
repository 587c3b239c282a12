#include <cmath>

#include "matbake/validate_params.hpp"

namespace matbake::validate {
const params::Group<Options>& options_params() {
  using params::Spec;
  static const params::Group<Options> group{{
      params::number<Options>(Spec{.name = "tolerance",
                                   .help = "With a reference material: relative tolerance of F0 per channel",
                                   .min = 0, .max = HUGE_VAL, .above_min = true, .example = "0.2"},
                              [](auto& o) -> auto& { return o.tolerance; }),
      params::number<Options>(Spec{.name = "max_violations",
                                   .help = "Flagged share of unmasked texels allowed before the check fails (see gate)",
                                   .min = 0, .max = 1, .example = "0.5"},
                              [](auto& o) -> auto& { return o.max_violations; }),
      params::flag<Options>(Spec{.name = "gate",
                                 .help = "Whether more flagged texels than max_violations fail (validate: exit 3; a "
                                         "build: the job fails and writes no textures, and the scenes using the "
                                         "material are skipped); off (the default): advisory, reported and "
                                         "counted only",
                                 .example = "true"},
                            [](auto& o) -> auto& { return o.gate; }),
      params::integer<Options>(Spec{.name = "worst", .help = "How many of the worst texels the report lists", .min = 0,
                                    .max = 1e6, .example = "3"},
                               [](auto& o) -> auto& { return o.worst_count; }),
  }};
  return group;
}

}  // namespace matbake::validate
