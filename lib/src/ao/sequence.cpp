#include "sequence.hpp"

namespace matbake::ao {

Sample2 sample(Sampler sampler, std::uint32_t i, std::uint64_t key) { return Sequence(sampler, key)[i]; }

}  // namespace matbake::ao
