#pragma once
// The AO rays' directions: the per-point sample sequence (ao.hpp's sample()) with its scramble
// worked out once, its Sobol dimension, and a cosine and sine without a library call, the three
// parts of aiming a ray that showed in a profile of the bake.
#include <algorithm>
#include <array>
#include <cstdint>
#include <numbers>
#include <utility>

#include "matbake/ao.hpp"

namespace matbake::ao {

// Inline: a bake aims billions of rays, and each of these was a call (through the library's PLT);
// the hottest are always inlined.
namespace sequence_detail {

inline std::uint64_t mix(std::uint64_t x) {  // splitmix64's finalizer: a well-spread 64-bit hash
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

inline std::uint32_t reverse_bits(std::uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Sobol's second dimension (primitive polynomial x + 1): with the van der Corput first dimension
// a (0, 2)-sequence in base 2. Bit j of i adds direction number V_j (V_0 = 2^31, V_j+1 = V_j ^
// V_j >> 1); the sum is an XOR, so it is linear in i's bits, and taken a byte at a time from
// tables of each byte's sum (a bit loop's branches were a tenth of an AO bake).
constexpr std::uint32_t sobol_second_bits(std::uint32_t i) {
  std::uint32_t r = 0;
  for (std::uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1) r ^= (i & 1) ? v : 0;
  return r;
}

using ByteTables = std::array<std::array<std::uint32_t, 256>, 4>;

constexpr ByteTables sobol_second_tables() {
  ByteTables tables{};
  for (std::uint32_t byte = 0; byte < 4; ++byte) {
    for (std::uint32_t b = 0; b < 256; ++b) tables[byte][b] = sobol_second_bits(b << (8 * byte));
  }
  return tables;
}

inline constexpr ByteTables kSobolSecond = sobol_second_tables();

inline constexpr float kTwoToMinus32 = 2.3283064365386963e-10f;

inline float unit(std::uint32_t bits) { return std::min(float(bits) * kTwoToMinus32, 0x1.fffffep-1f); }

}  // namespace sequence_detail

// One point's sequence: sequence[i] == sample(sampler, i, key).
class Sequence {
 public:
  Sequence(Sampler sampler, std::uint64_t key);
  Sample2 operator[](std::uint32_t i) const;

 private:
  Sampler sampler_;
  std::uint64_t key_, scramble_;
};

// The unscrambled bits of sample i's second Sobol coordinate (v, times 2^32).
inline std::uint32_t sobol_second(std::uint32_t i) {
  const sequence_detail::ByteTables& t = sequence_detail::kSobolSecond;
  return t[0][i & 255] ^ t[1][(i >> 8) & 255] ^ t[2][(i >> 16) & 255] ^ t[3][i >> 24];
}

inline Sequence::Sequence(Sampler sampler, std::uint64_t key)
    : sampler_(sampler), key_(key), scramble_(sequence_detail::mix(key)) {}

[[gnu::always_inline]] inline Sample2 Sequence::operator[](std::uint32_t i) const {
  using namespace sequence_detail;
  if (sampler_ == Sampler::sobol) {
    return {unit(reverse_bits(i) ^ std::uint32_t(scramble_)), unit(sobol_second(i) ^ std::uint32_t(scramble_ >> 32))};
  }
  const std::uint64_t bits = mix(key_ ^ mix(i));
  return {unit(std::uint32_t(bits)), unit(std::uint32_t(bits >> 32))};
}

// (cos 2πv, sin 2πv) for v in [0, 1), within 2e-7 of the true values (a float's step near 1 is
// 6e-8 below it, 1.2e-7 above), and more exact than sincos(2π·v), whose argument is rounded once
// before the call.
[[gnu::always_inline]] inline std::pair<float, float> unit_circle(float v) {
  // 2πv = q·π/2 + θ with q the nearest quarter turn and θ in [−π/4, π/4]; 4v and 4v − q are exact.
  const float quarters = 4 * v;
  const int q = int(quarters + 0.5f);  // v ≥ 0: truncation is the floor
  const float theta = (quarters - float(q)) * (std::numbers::pi_v<float> / 2), t2 = theta * theta;
  // Taylor series to θ⁹ and θ¹⁰: the first terms left out are below 2e-9 at |θ| = π/4.
  const float s = theta * (1 + t2 * (-1.0f / 6 + t2 * (1.0f / 120 + t2 * (-1.0f / 5040 + t2 * (1.0f / 362880)))));
  const float c = 1 + t2 * (-0.5f + t2 * (1.0f / 24 + t2 * (-1.0f / 720 + t2 * (1.0f / 40320 - t2 * (1.0f / 3628800)))));
  // Turning by q quarters: (c, s) → (−s, c) → (−c, −s) → (s, −c); as selects, not branches.
  const bool odd = (q & 1) != 0;
  const float sign = (q & 2) ? -1.0f : 1.0f;
  return {sign * (odd ? -s : c), sign * (odd ? c : s)};
}

}  // namespace matbake::ao
