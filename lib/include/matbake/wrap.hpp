#pragma once
// A glTF sampler's wrap mode along one axis (wrapS, wrapT): where a read past a texture's edge
// lands. One type for every module that samples a texture as a runtime will (the texture transform
// resampler, AO's texel rasteriser, delivery's mip filters).
#include <algorithm>

namespace matbake {

enum class Wrap { repeat, mirrored_repeat, clamp_to_edge };

// glTF's values: 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT, anything else (10497, absent) REPEAT.
inline Wrap wrap_from_gltf(long long value) {
  return value == 33071 ? Wrap::clamp_to_edge : value == 33648 ? Wrap::mirrored_repeat : Wrap::repeat;
}

// Texel `i` of an axis of `n` texels (n > 0), wrapped into [0, n).
inline long long wrapped_index(long long i, long long n, Wrap wrap) {
  if (i >= 0 && i < n) return i;  // the common case, the same in every mode
  switch (wrap) {
    case Wrap::clamp_to_edge: return std::clamp(i, 0LL, n - 1);
    case Wrap::mirrored_repeat: {
      const long long m = ((i % (2 * n)) + 2 * n) % (2 * n);
      return m < n ? m : 2 * n - 1 - m;
    }
    case Wrap::repeat: break;
  }
  return ((i % n) + n) % n;
}

}  // namespace matbake
