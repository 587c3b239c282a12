#include "support/simplify.hpp"

#include <meshoptimizer.h>

#include <numeric>
#include <stdexcept>

#include "lib/src/gltf/decode.hpp"
#include "lib/src/gltf/document.hpp"

namespace matbake::test {

void write_simplified(const std::filesystem::path& input, const std::filesystem::path& output, double ratio) {
  auto doc = gltf::read_document(input);
  if (!doc) throw std::runtime_error(doc.error().message);
  for (std::size_t m = 0; m < doc->json["meshes"].size(); ++m) {
    for (std::size_t p = 0; p < doc->json["meshes"][m]["primitives"].size(); ++p) {
      gltf::uncompress_draco_primitive(*doc, m, p);  // its indices change: written uncompressed
      gltf::Json& primitive = doc->json["meshes"][m]["primitives"][p];
      if (gltf::integer_in<int>(primitive, "mode", gltf::kTriangles, -1) != gltf::kTriangles) continue;
      auto positions = gltf::accessor_bytes(*doc, gltf::size_in(primitive["attributes"], "POSITION", SIZE_MAX));
      if (!positions) throw std::runtime_error(positions.error().message);
      std::vector<float> xyz;
      for (std::size_t v = 0; v < positions->count; ++v) {
        for (std::size_t c = 0; c < 3; ++c) {
          xyz.push_back(gltf::component_value(positions->first + v * positions->stride + c * positions->component_size,
                                              positions->component_type, positions->normalized));
        }
      }
      std::vector<unsigned> indices(positions->count);
      std::iota(indices.begin(), indices.end(), 0u);
      if (primitive.contains("indices")) {
        auto bytes = gltf::accessor_bytes(*doc, gltf::size_in(primitive, "indices", SIZE_MAX));
        if (!bytes) throw std::runtime_error(bytes.error().message);
        indices.resize(bytes->count);
        for (std::size_t i = 0; i < bytes->count; ++i) indices[i] = gltf::index_value(bytes->first + i * bytes->stride, bytes->component_type);
      }
      const std::size_t target = std::size_t(double(indices.size() / 3) * ratio) * 3;
      std::vector<unsigned> simplified(indices.size());
      simplified.resize(meshopt_simplify(simplified.data(), indices.data(), indices.size(), xyz.data(), positions->count,
                                         3 * sizeof(float), target, 1.0f, meshopt_SimplifyLockBorder, nullptr));
      const auto bytes = std::span(reinterpret_cast<const unsigned char*>(simplified.data()), simplified.size() * 4);
      const int view = gltf::add_view(*doc, bytes, gltf::kElementArrayBuffer);
      doc->json["accessors"].push_back(
          {{"bufferView", view}, {"componentType", gltf::kUnsignedInt}, {"count", simplified.size()}, {"type", "SCALAR"}});
      doc->json["meshes"][m]["primitives"][p]["indices"] = doc->json["accessors"].size() - 1;
    }
  }
  auto written = gltf::write_document(*doc, output);
  if (!written) throw std::runtime_error(written.error().message);
}

}  // namespace matbake::test
