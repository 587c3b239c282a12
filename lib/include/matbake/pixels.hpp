#pragma once
// Interleaved pixel kernels: per channel a transfer, so alpha (and later data channels such as
// gloss or masks) is never gamma-converted. Parallel over pixels with TBB.
#include <cstdint>
#include <span>

#include "matbake/color.hpp"

namespace matbake::color {

// Per-channel transfers of an interleaved buffer with channels.size() channels (1 to 4).
using ChannelTransfers = std::span<const Transfer>;

// Decode stored samples to linear float. Integer samples are normalised (code / (2^bits - 1));
// half samples are given as their 16-bit patterns.
void decode_pixels(std::span<const uint8_t> in, std::span<float> out, ChannelTransfers transfers);
void decode_pixels(std::span<const uint16_t> in, std::span<float> out, ChannelTransfers transfers);
void decode_half_pixels(std::span<const uint16_t> in, std::span<float> out, ChannelTransfers transfers);
void decode_pixels(std::span<const float> in, std::span<float> out, ChannelTransfers transfers);

// Encode linear float to stored samples (exact quantize() for integers, the fast path for float).
void encode_pixels(std::span<const float> in, std::span<uint8_t> out, ChannelTransfers transfers);
void encode_pixels(std::span<const float> in, std::span<uint16_t> out, ChannelTransfers transfers);
void encode_pixels(std::span<const float> in, std::span<float> out, ChannelTransfers transfers);

}  // namespace matbake::color
