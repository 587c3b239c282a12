// Every float in [0, 1] through the fast float path, against float(float64 formula): how many are
// equal, 1 ulp off, and more; and through the 8-bit quantizer, against rounding the formula. The
// unit tests sample this; this program runs all 1.07e9 (minutes).
#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

#include "matbake/color.hpp"
#include "matbake/pixels.hpp"

int main() {
  using matbake::color::Transfer;
  const uint32_t one = std::bit_cast<uint32_t>(1.0f);
  for (Transfer t : {Transfer::srgb, Transfer::gamma22}) {
    for (bool decode : {true, false}) {
      tbb::combinable<std::array<uint64_t, 3>> counts([] { return std::array<uint64_t, 3>{}; });
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, one + 1, 1 << 16), [&](const auto& r) {
        auto& c = counts.local();
        for (uint32_t b = r.begin(); b != r.end(); ++b) {
          const float x = std::bit_cast<float>(b);
          const float fast = decode ? matbake::color::linear_from_encoded_fast(t, x)
                                    : matbake::color::encoded_from_linear_fast(t, x);
          const float exact = float(decode ? matbake::color::linear_from_encoded(t, x)
                                           : matbake::color::encoded_from_linear(t, x));
          const int64_t d = std::llabs(int64_t(std::bit_cast<int32_t>(fast)) - int64_t(std::bit_cast<int32_t>(exact)));
          ++c[d == 0 ? 0 : d == 1 ? 1 : 2];
        }
      });
      std::array<uint64_t, 3> total{};
      counts.combine_each([&](const auto& c) {
        for (int i = 0; i < 3; ++i) total[i] += c[i];
      });
      std::printf("%-8s %-6s floats in [0,1]: %llu exact, %llu at 1 ulp, %llu beyond\n",
                  std::string(matbake::color::transfer_name(t)).c_str(), decode ? "decode" : "encode",
                  (unsigned long long)total[0], (unsigned long long)total[1], (unsigned long long)total[2]);
    }
  }
  // The 8-bit quantizer of every write (encode_pixels, batches of 2^16) against rounding the
  // float64 formula: the count of wrong codes must be 0.
  for (Transfer t : {Transfer::linear, Transfer::srgb, Transfer::gamma22}) {
    tbb::combinable<uint64_t> wrong([] { return uint64_t{0}; });
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, uint64_t(one) + 1, 1 << 16), [&](const auto& r) {
      std::vector<float> in(r.size());
      std::vector<uint8_t> codes(r.size());
      for (uint64_t b = r.begin(); b != r.end(); ++b) in[b - r.begin()] = std::bit_cast<float>(uint32_t(b));
      const Transfer transfers[] = {t};
      matbake::color::encode_pixels(in, codes, transfers);
      for (std::size_t i = 0; i < in.size(); ++i) wrong.local() += codes[i] != matbake::color::quantize_reference(t, 8, in[i]);
    });
    std::printf("%-8s 8-bit quantizer, floats in [0,1]: %llu wrong codes\n", std::string(matbake::color::transfer_name(t)).c_str(),
                (unsigned long long)wrong.combine(std::plus<>()));
  }
  return 0;
}
