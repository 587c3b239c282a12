// Exact tables: decode of every 8-bit, 16-bit and half code, and the decision thresholds that make
// quantize() equal to rounding the float64 formula. Built in float64 on first use, once per process.
#include <Imath/half.h>

#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <vector>

#include "matbake/color.hpp"
#include "quantizer.hpp"

namespace matbake::color {
namespace {

constexpr std::array<Transfer, 3> kTransfers = {Transfer::linear, Transfer::srgb, Transfer::gamma22};

int max_code(int bits) { return (1 << bits) - 1; }

std::vector<float> build_decode_table(Transfer transfer, int bits) {
  const int max = max_code(bits);
  std::vector<float> table(std::size_t(max) + 1);
  for (int code = 0; code <= max; ++code) {
    table[code] = float(linear_from_encoded(transfer, double(code) / max));
  }
  return table;
}

std::vector<float> build_half_table(Transfer transfer) {
  std::vector<float> table(65536);
  for (unsigned bits = 0; bits < 65536; ++bits) {
    Imath::half h;
    h.setBits(static_cast<unsigned short>(bits));
    table[bits] = float(linear_from_encoded(transfer, double(float(h))));
  }
  return table;
}

template <int Bits>
const std::vector<float>& decode_table_of(Transfer transfer) {
  static const std::array<std::vector<float>, 3> tables = {build_decode_table(kTransfers[0], Bits),
                                                           build_decode_table(kTransfers[1], Bits),
                                                           build_decode_table(kTransfers[2], Bits)};
  return tables[std::size_t(transfer)];
}

Quantizer build_quantizer(Transfer transfer, int bits) {
  const int max = max_code(bits);
  Quantizer q;
  q.max = max;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  q.threshold.assign(std::size_t(max) + 2, 0.0f);
  q.threshold[std::size_t(max) + 1] = kInf;
  for (int k = 1; k <= max; ++k) {
    float x = float(linear_from_encoded(transfer, (k - 0.5) / max));
    while (quantize_reference(transfer, bits, x) >= k) x = std::nextafter(x, -kInf);
    while (quantize_reference(transfer, bits, x) < k) x = std::nextafter(x, kInf);
    q.threshold[k] = x;
  }
  const uint32_t last_bucket = std::bit_cast<uint32_t>(1.0f) >> QuantizerView::kBucketShift;
  for (uint32_t b = 0; b <= last_bucket; ++b) {
    q.bucket_code.push_back(quantize_reference(transfer, bits, std::bit_cast<float>(b << QuantizerView::kBucketShift)));
  }
  // The codes of a bucket's first and last floats: one_step holds when they never differ by more
  // than one (code_of_one_step is then exact).
  q.one_step = true;
  for (uint32_t b = 0; b < last_bucket; ++b) {
    const float last = std::bit_cast<float>(((b + 1) << QuantizerView::kBucketShift) - 1);
    q.one_step = q.one_step && quantize_reference(transfer, bits, last) - q.bucket_code[b] <= 1;
  }
  return q;
}

template <int Bits>
const Quantizer& quantizer_of(Transfer transfer) {
  static const std::array<Quantizer, 3> quantizers = {build_quantizer(kTransfers[0], Bits),
                                                      build_quantizer(kTransfers[1], Bits),
                                                      build_quantizer(kTransfers[2], Bits)};
  return quantizers[std::size_t(transfer)];
}

}  // namespace

std::span<const float> decode_table(Transfer transfer, int bits) {
  return bits == 16 ? decode_table_of<16>(transfer) : decode_table_of<8>(transfer);
}

std::span<const float> decode_table_half(Transfer transfer) {
  static const std::array<std::vector<float>, 3> tables = {
      build_half_table(kTransfers[0]), build_half_table(kTransfers[1]), build_half_table(kTransfers[2])};
  return tables[std::size_t(transfer)];
}

uint16_t quantize_reference(Transfer transfer, int bits, double linear) {
  const int max = max_code(bits);
  const double code = std::floor(encoded_from_linear(transfer, linear) * max + 0.5);
  if (!(code > 0)) return 0;  // also NaN
  return code >= max ? uint16_t(max) : uint16_t(code);
}

const Quantizer& quantizer(Transfer transfer, int bits) {
  return bits == 16 ? quantizer_of<16>(transfer) : quantizer_of<8>(transfer);
}

uint16_t quantize(Transfer transfer, int bits, float linear) { return quantizer(transfer, bits).view().code_of(linear); }

}  // namespace matbake::color
