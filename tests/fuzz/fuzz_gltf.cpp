// glTF loading: the document (JSON, references, buffers, Draco / meshopt / sparse decoding, accessor
// checks) and the flattened scene built from it,
// as export and bake-ao read them, the texel coverage of a texture bake over its UVs, and the
// geometry pass of delivery (quantization, meshopt compression) over the document. MATBAKE_FUZZ_EXTENSION is ".gltf" or ".glb" (two targets).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "lib/src/ao/texels.hpp"
#include "lib/src/bake_ao/textures.hpp"
#include "lib/src/delivery/geometry.hpp"
#include "lib/src/gltf/document.hpp"
#include "lib/src/gltf/texture_transform.hpp"
#include "lib/src/scene/from_document.hpp"

namespace {

std::filesystem::path scratch;  // a folder of this process's own: the input is a file in it
// One thread: a unit's work is small (spreading it costs more than it gains), and two targets run
// side by side on a two-core machine each keep one core.
std::unique_ptr<tbb::global_control> one_thread;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  scratch = std::filesystem::temp_directory_path() / ("matbake-fuzz-" + std::to_string(getpid()));
  std::filesystem::create_directories(scratch);
  one_thread = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = scratch / (std::string("input") + MATBAKE_FUZZ_EXTENSION);
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  auto doc = matbake::gltf::read_document(file);
  if (!doc) return 0;
  // With the UV sets, and each material's texel coverage at a small size (no rays: the
  // rasterization, tie rule and wrap modes see the file's UVs).
  auto scene = matbake::scene::scene_from_document(*doc, {.texcoords = true});
  if (scene) {
    auto targets = matbake::bake_ao::occlusion_targets(*doc, *scene, matbake::ao::TextureRequest{});
    // One wrap mode per target, taken in turn (all three reached with three materials): every
    // mode for every target tripled the cost of a many-material input and halved the run's speed.
    constexpr matbake::ao::Wrap kWraps[] = {matbake::ao::Wrap::repeat, matbake::ao::Wrap::mirrored_repeat,
                                            matbake::ao::Wrap::clamp_to_edge};
    for (std::size_t t = 0; targets && t < targets->targets.size(); ++t) {
      auto target = targets->targets[t];
      target.wrap_s = kWraps[t % 3];
      target.wrap_t = kWraps[(t + 1) % 3];
      (void)matbake::ao::texels::cover(*scene, target, 16, 8);
    }
  }
  // Each material's occlusion transform, sampled over a tiny texture.
  matbake::image::Image tiny;
  tiny.width = tiny.height = 2, tiny.channels = 1, tiny.pixels = {0.0f, 1.0f, 0.5f, 0.25f};
  for (const auto& material : matbake::gltf::array_in(doc->json, "materials")) {
    if (!material.is_object() || !material.contains("occlusionTexture")) continue;
    auto transform = matbake::gltf::uv_transform_of(material["occlusionTexture"], doc->file, "/materials");
    if (transform) (void)matbake::gltf::sample_through(tiny, *transform, matbake::ao::Wrap::mirrored_repeat, matbake::ao::Wrap::repeat, 3, 3);
  }
  for (std::size_t i = 0; doc->json.contains("images") && doc->json["images"].is_array() && i < doc->json["images"].size(); ++i) {
    (void)matbake::gltf::image_bytes(*doc, i);
  }
  // Geometry for delivery, quantized and compressed, over whatever the file holds; then every
  // accessor still reads.
  const matbake::delivery::GeometryOptions geometry{.quantize = true, .compression = matbake::delivery::MeshCompression::meshopt};
  if (matbake::delivery::deliver_geometry(*doc, geometry)) {
    for (std::size_t i = 0; i < matbake::gltf::array_in(doc->json, "accessors").size(); ++i) (void)matbake::gltf::accessor_bytes(*doc, i);
  }
  return 0;
}
