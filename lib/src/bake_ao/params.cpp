#include "matbake/bake_ao_params.hpp"

#include "matbake/ao_params.hpp"
#include "matbake/delivery_params.hpp"
#include "matbake/encoding_params.hpp"

namespace matbake::bake_ao {

const params::Tree<Options>& request_tree() {
  static const params::Tree<Options> tree{
      params::branch<Options>(image::encoding_params(), "", "", [](auto& o) -> auto& { return o.encoding; }),
      params::branch<Options>(delivery::options_params(), "", "", [](auto& o) -> auto& { return o.delivery; }),
      params::branch<Options>(ao::request_params(), "ao", "", [](auto& o) -> auto& { return o.ao; }),
  };
  return tree;
}

}  // namespace matbake::bake_ao
