#pragma once
// KHR_texture_transform: the UV transform a textureInfo applies before sampling (offset, rotation,
// scale, and a texCoord override), and a texture resampled through it onto raw UVs, so that a
// texture combined texel by texel with one over untransformed UVs (a baked occlusion) lines up.
#include <glm/vec2.hpp>

#include "document.hpp"
#include "matbake/wrap.hpp"
#include "matbake/image.hpp"

namespace matbake::gltf {

struct UvTransform {
  glm::dvec2 offset{0.0}, scale{1.0};
  double rotation = 0;  // radians
  int texcoord = -1;    // the extension's texCoord, overriding the textureInfo's; -1: none
  bool identity() const { return offset == glm::dvec2(0.0) && scale == glm::dvec2(1.0) && rotation == 0; }
  // uv' = offset + R(rotation) (scale ⊙ uv), R as the extension's GLSL writes it.
  glm::dvec2 apply(glm::dvec2 uv) const;
};

// The KHR_texture_transform of `info` (a textureInfo); identity when it has none. A malformed one is
// an error naming `where` ("/materials/0/occlusionTexture").
Result<UvTransform> uv_transform_of(const Json& info, const std::string& file, const std::string& where);

// `source` at uv sampled bilinearly as a GPU does (texel centres at half-integers), wrapped per the
// sampler's modes: one value per channel into `out`.
void sample_bilinear(const image::Image& source, glm::dvec2 uv, Wrap wrap_s, Wrap wrap_t, float* out);

// A width × height image over raw UVs: texel (x, y) holds `source` sampled bilinearly (as a GPU does,
// texel centres at half-integers) at transform((x + ½) / width, (y + ½) / height), wrapped per the
// sampler's modes.
image::Image sample_through(const image::Image& source, const UvTransform& transform, Wrap wrap_s, Wrap wrap_t,
                            int width, int height);

// A glTF sampler's wrap mode (10497 repeat, 33648 mirrored repeat, 33071 clamp); repeat by default.
Wrap wrap_of(const Json& sampler, const char* key);

}  // namespace matbake::gltf
