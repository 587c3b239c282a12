#include "report_json.hpp"

namespace matbake::cli {

nlohmann::json to_json(const workflow::ErrorStats& s) {
  return {{"mean", s.mean}, {"max", s.max}, {"max_at", {s.max_x, s.max_y}}, {"texels", s.count}};
}

nlohmann::json to_json(const workflow::ConversionErrors& e) {
  return {{"diffuse_delta_e_ab", to_json(e.diffuse_delta_e)}, {"specular_f0_abs", to_json(e.specular)},
          {"lobe_relative_rms", to_json(e.lobe)}};
}

nlohmann::json to_json(const workflow::DielectricF0& d) {
  return {{"texels", d.texels},
          {"mean_f0", d.mean_f0},
          {"KHR_materials_ior", {{"ior", d.ior}}},
          {"KHR_materials_specular", {{"specularColorFactor", d.specular_color_factor}}},
          {"error_without_extensions", to_json(d.error_without_extensions)},
          {"error_with_extensions", to_json(d.error_with_extensions)}};
}

}  // namespace matbake::cli
