// Matching low-poly parts to high-poly parts by name (bake.hpp's Match::by_name).
#include <algorithm>
#include <map>

#include "matbake/bake.hpp"

namespace matbake::bake {

std::string_view part_key(std::string_view name, std::string_view suffix) {
  return name.substr(0, name.find(suffix));  // npos: the whole name
}

PartMatch match_parts(const scene::Scene& low, const scene::Scene& high) {
  PartMatch out;
  std::map<std::string_view, std::uint32_t> number;  // a high part's key, numbered as first met
  for (const scene::Instance& inst : high.instances) {
    out.high.push_back(number.try_emplace(part_key(inst.name, "_high"), std::uint32_t(number.size())).first->second);
  }
  // A low part no high part matches: a number past every high part's, so its rays meet nothing.
  const auto unmatched = std::uint32_t(high.instances.size());
  for (const scene::Instance& inst : low.instances) {
    const auto found = number.find(part_key(inst.name, "_low"));
    out.low.push_back(found == number.end() ? unmatched : found->second);
    if (found == number.end() && std::find(out.unmatched.begin(), out.unmatched.end(), inst.name) == out.unmatched.end()) {
      out.unmatched.push_back(inst.name);
    }
  }
  return out;
}

}  // namespace matbake::bake
