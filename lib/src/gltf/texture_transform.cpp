#include "texture_transform.hpp"

#include <cmath>

namespace matbake::gltf {
namespace {

// A texel index on one axis of `size` texels, wrapped.
int wrapped(long long i, int size, Wrap wrap) { return int(wrapped_index(i, size, wrap)); }

Result<glm::dvec2> pair_in(const Json& ext, const char* key, glm::dvec2 fallback, const std::string& file, const std::string& where) {
  if (!ext.contains(key)) return fallback;
  const Json& v = ext[key];
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number()) {
    return Error{file, where + "/extensions/KHR_texture_transform/" + key + ": not two numbers"};
  }
  return glm::dvec2(v[0].get<double>(), v[1].get<double>());
}

}  // namespace

glm::dvec2 UvTransform::apply(glm::dvec2 uv) const {
  const double c = std::cos(rotation), s = std::sin(rotation);
  const glm::dvec2 scaled = uv * scale;
  // The extension's GLSL builds mat3(cos, sin, 0, −sin, cos, 0, 0, 0, 1), whose columns are
  // (cos, sin) and (−sin, cos).
  return offset + glm::dvec2(c * scaled.x - s * scaled.y, s * scaled.x + c * scaled.y);
}

Result<UvTransform> uv_transform_of(const Json& info, const std::string& file, const std::string& where) {
  UvTransform t;
  if (!info.is_object() || !info.contains("extensions") || !info["extensions"].is_object() ||
      !info["extensions"].contains("KHR_texture_transform")) {
    return t;
  }
  const Json& ext = info["extensions"]["KHR_texture_transform"];
  if (!ext.is_object()) return Error{file, where + "/extensions/KHR_texture_transform: not an object"};
  auto offset = pair_in(ext, "offset", glm::dvec2(0.0), file, where);
  auto scale = pair_in(ext, "scale", glm::dvec2(1.0), file, where);
  if (!offset) return offset.error();
  if (!scale) return scale.error();
  t.offset = *offset, t.scale = *scale;
  if (ext.contains("rotation")) {
    if (!ext["rotation"].is_number()) return Error{file, where + "/extensions/KHR_texture_transform/rotation: not a number"};
    t.rotation = ext["rotation"].get<double>();
  }
  t.texcoord = integer_in(ext, "texCoord", -1, -2);
  if (t.texcoord == -2) return Error{file, where + "/extensions/KHR_texture_transform/texCoord: not an index"};
  return t;
}

void sample_bilinear(const image::Image& source, glm::dvec2 uv, Wrap wrap_s, Wrap wrap_t, float* out) {
  const std::size_t channels = std::size_t(source.channels);
  const double sx = uv.x * source.width - 0.5, sy = uv.y * source.height - 0.5;
  const double fx = std::floor(sx), fy = std::floor(sy);
  const double wx = sx - fx, wy = sy - fy;
  const long long ix = static_cast<long long>(fx), iy = static_cast<long long>(fy);
  const int x0 = wrapped(ix, source.width, wrap_s), x1 = wrapped(ix + 1, source.width, wrap_s);
  const int y0 = wrapped(iy, source.height, wrap_t), y1 = wrapped(iy + 1, source.height, wrap_t);
  const auto at = [&](int tx, int ty, std::size_t c) {
    return double(source.pixels[(std::size_t(ty) * std::size_t(source.width) + std::size_t(tx)) * channels + c]);
  };
  for (std::size_t c = 0; c < channels; ++c) {
    const double top = at(x0, y0, c) * (1 - wx) + at(x1, y0, c) * wx;
    const double bottom = at(x0, y1, c) * (1 - wx) + at(x1, y1, c) * wx;
    out[c] = float(top * (1 - wy) + bottom * wy);
  }
}

image::Image sample_through(const image::Image& source, const UvTransform& transform, Wrap wrap_s, Wrap wrap_t,
                            int width, int height) {
  image::Image out;
  static_cast<image::ImageLayout&>(out) = source;
  out.width = width, out.height = height;
  out.pixels.assign(out.sample_count(), 0.0f);
  const std::size_t channels = std::size_t(source.channels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const glm::dvec2 uv = transform.apply({(x + 0.5) / width, (y + 0.5) / height});
      sample_bilinear(source, uv, wrap_s, wrap_t, &out.pixels[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * channels]);
    }
  }
  return out;
}

Wrap wrap_of(const Json& sampler, const char* key) { return wrap_from_gltf(integer_in<int>(sampler, key, 10497, 10497)); }

}  // namespace matbake::gltf
