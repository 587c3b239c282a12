#include <cmath>

#include "matbake/color.hpp"
#include "power_function.hpp"

namespace matbake::color {
namespace {

// IEC 61966-2-1 constants.
constexpr double kSrgbDecodeThreshold = 0.04045;
constexpr double kSrgbEncodeThreshold = 0.0031308;
constexpr double kSrgbSlope = 12.92;
constexpr double kSrgbOffset = 0.055;
constexpr double kSrgbScale = 1.055;
constexpr double kSrgbGamma = 2.4;
// Schüler's display gamma.
constexpr double kGamma22 = 2.2;

// The four power functions the fast path needs, built once.
const PowerFunction& power_function(Transfer transfer, bool decode) {
  static const PowerFunction srgb_decode(kSrgbGamma), srgb_encode(1.0 / kSrgbGamma);
  static const PowerFunction gamma22_decode(kGamma22), gamma22_encode(1.0 / kGamma22);
  if (transfer == Transfer::srgb) return decode ? srgb_decode : srgb_encode;
  return decode ? gamma22_decode : gamma22_encode;
}

// The two formulas share their shape; `power` is std::pow in the reference and a PowerFunction on
// the fast path, so both paths evaluate the same float64 expression.
template <class Power>
double decode_magnitude(Transfer transfer, double v, const Power& power) {
  switch (transfer) {
    case Transfer::linear: return v;
    case Transfer::srgb:
      return v <= kSrgbDecodeThreshold ? v / kSrgbSlope : power((v + kSrgbOffset) / kSrgbScale);
    case Transfer::gamma22: return power(v);
  }
  return v;
}

template <class Power>
double encode_magnitude(Transfer transfer, double l, const Power& power) {
  switch (transfer) {
    case Transfer::linear: return l;
    case Transfer::srgb:
      return l <= kSrgbEncodeThreshold ? l * kSrgbSlope : kSrgbScale * power(l) - kSrgbOffset;
    case Transfer::gamma22: return power(l);
  }
  return l;
}

struct StdPow {
  double exponent;
  double operator()(double x) const { return std::pow(x, exponent); }
};

double decode_exponent(Transfer transfer) { return transfer == Transfer::srgb ? kSrgbGamma : kGamma22; }

}  // namespace

double linear_from_encoded(Transfer transfer, double encoded) {
  const StdPow power{decode_exponent(transfer)};
  return std::copysign(decode_magnitude(transfer, std::fabs(encoded), power), encoded);
}

double encoded_from_linear(Transfer transfer, double linear) {
  const StdPow power{1.0 / decode_exponent(transfer)};
  return std::copysign(encode_magnitude(transfer, std::fabs(linear), power), linear);
}

float linear_from_encoded_fast(Transfer transfer, float encoded) {
  const PowerFunction& power = power_function(transfer, true);
  const double v = encoded;
  return float(std::copysign(decode_magnitude(transfer, std::fabs(v), power), v));
}

float encoded_from_linear_fast(Transfer transfer, float linear) {
  const PowerFunction& power = power_function(transfer, false);
  const double l = linear;
  return float(std::copysign(encode_magnitude(transfer, std::fabs(l), power), l));
}

}  // namespace matbake::color
