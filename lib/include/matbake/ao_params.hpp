#pragma once
// The parameters of an AO bake (ao::Request): `bake-ao`'s options, `export --ao-*` and a manifest
// scene's `ao = { ... }`, described once (params.hpp).
#include "matbake/ao.hpp"
#include "matbake/params.hpp"

namespace matbake::ao {

const params::Group<Request>& request_params();
// Of those, the estimator's own (Request::options: samples, distances, falloff, bias, sides, seed,
// sampler, traversal), for a bake that traces AO from points it finds itself (bake's `ao-*`).
const params::Group<Request>& estimator_params();

// Where per-vertex AO goes, as two parameters over one Into (R::*into): `attribute`, COLOR_0 or _AO,
// and `existing`, what happens to a primitive's own COLOR_0 (multiply or replace; it needs
// `attribute` = COLOR_0). The specs bring name, help and the rules beyond that one.
template <class R>
params::Param<R> into_attribute(params::Spec spec, Into R::*into) {
  spec.kind = params::Kind::choice;
  spec.choices = {"COLOR_0", "_AO"};
  return {std::move(spec),
          [into](R& r, const params::Value& v) -> std::optional<std::string> {
            r.*into = *into_from_names(std::get<std::string>(v), into_existing_colors_name(r.*into));
            return std::nullopt;
          },
          [into](const R& r) { return nlohmann::json(std::string(into_attribute_name(r.*into))); }};
}
template <class R>
params::Param<R> into_existing(params::Spec spec, const std::string& attribute, Into R::*into) {
  spec.kind = params::Kind::choice;
  spec.choices = {"multiply", "replace"};
  spec.needs.push_back({attribute, "COLOR_0"});
  return {std::move(spec),
          [into](R& r, const params::Value& v) -> std::optional<std::string> {
            if (r.*into != Into::attribute) r.*into = *into_from_names("COLOR_0", std::get<std::string>(v));
            return std::nullopt;
          },
          [into](const R& r) { return nlohmann::json(std::string(into_existing_colors_name(r.*into))); }};
}

}  // namespace matbake::ao
