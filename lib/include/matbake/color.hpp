#pragma once
// Transfer functions (the "gamma" of an encoding) and their exact and fast evaluation.
//
// Reference formulas are float64; every faster path is defined and tested against them:
// - 8/16-bit decode tables hold the correctly rounded float32 of the float64 formula;
// - quantize() rounds the float64 formula to the nearest code, exactly, for every float input;
// - the fast float path is within 1 ulp of the float64 formula (docs/convert.md gives the measured
//   distribution).
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "matbake/enum_names.hpp"

namespace matbake::color {

enum class Transfer {
  linear,   // identity
  srgb,     // IEC 61966-2-1: linear toe below 0.04045 (decode) / 0.0031308 (encode), then 2.4 power
  gamma22,  // pure power 2.2, the display gamma of Schüler's article
};

inline constexpr NameTable<Transfer, 3> kTransferNames{
    {{Transfer::srgb, "srgb"}, {Transfer::gamma22, "gamma2.2"}, {Transfer::linear, "linear"}}};
inline std::optional<Transfer> transfer_from_name(std::string_view name) { return value_in(kTransferNames, name); }
inline std::string_view transfer_name(Transfer transfer) { return name_in(kTransferNames, transfer); }

// float64 reference formulas. Odd-symmetric: a negative value is decoded (encoded) as the negative
// of its magnitude's value, so the curves stay monotone and invertible on the whole real line. HDR
// values above 1 follow the same formula.
double linear_from_encoded(Transfer transfer, double encoded);
double encoded_from_linear(Transfer transfer, double linear);

// Fast float paths: the float64 formula with a tabulated power function (power_function.hpp).
float linear_from_encoded_fast(Transfer transfer, float encoded);
float encoded_from_linear_fast(Transfer transfer, float linear);

// Exact decode tables: entry i is float(linear_from_encoded(transfer, i / (2^bits - 1))).
// bits is 8 or 16.
std::span<const float> decode_table(Transfer transfer, int bits);

// Exact decode of every half-float bit pattern (65536 entries; NaN and Inf patterns map to NaN and
// Inf).
std::span<const float> decode_table_half(Transfer transfer);

// Code of a linear value: clamp(floor(encoded_from_linear(x) * (2^bits - 1) + 0.5), 0, 2^bits - 1)
// computed in float64, for every float x; NaN gives 0. bits is 8 or 16.
uint16_t quantize(Transfer transfer, int bits, float linear);

// The same rule, evaluated directly in float64 (slow; the reference quantize() is tested against).
uint16_t quantize_reference(Transfer transfer, int bits, double linear);

}  // namespace matbake::color
