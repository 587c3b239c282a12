#pragma once
// A real runtime: three.js (tests/runtime, npm, pinned) in Debian's Chromium, headless with
// SwiftShader (tests/runtime/render.mjs, installed by scripts/install-runtime.sh). Each model is
// rendered from three fixed views under a fixed light; what three.js made of each texture is read
// back. Tests skip, saying why, only where the harness or Chromium is missing.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "support/render_psnr.hpp"  // the renders compared

namespace matbake::test {

// One material slot as three.js loaded it.
struct RuntimeTexture {
  std::string material;     // the three.js material's name (the glTF material's)
  std::string slot;         // "baseColorTexture", "normalTexture", ...
  int texture = -1;         // the glTF texture index it came from
  std::string color_space;  // "srgb", "srgb-linear" or "" (none: data)
  bool compressed = false;  // a transcoded KTX2 texture
  int width = 0, height = 0;
  int levels = 0;           // mip levels in the file (1 for PNG: three.js makes its own)
  bool generate_mipmaps = false;
  std::string min_filter;   // "linear_mipmap_linear", "linear", ...
};

struct RuntimeModel {
  std::vector<RuntimeTexture> textures;
  std::vector<std::string> console;  // every warning and error the page raised while loading it
  std::map<std::string, std::filesystem::path> renders;  // view ("fit", "near", "far") → PNG
};

inline const std::vector<std::string> kRuntimeViews = {"fit", "near", "far"};

// Renders each (name, file) into `folder`; empty with `why_not` when the harness cannot run here.
// A harness that runs and fails is not a skip: it throws std::runtime_error with its message.
std::optional<std::map<std::string, RuntimeModel>> render_in_three(
    const std::filesystem::path& folder, const std::vector<std::pair<std::string, std::filesystem::path>>& models,
    std::string& why_not);

// What Chromium shows of an HTML page (tests/runtime/check_page.mjs): console messages, each image's
// src and natural size, section ids, headings, script count (also left beside the page as
// PAGE.chromium.json); with `screenshot`, the whole page as PNG. Empty with `why_not` when the harness cannot run here; a harness failure throws.
std::optional<nlohmann::json> check_page_in_chromium(const std::filesystem::path& page, const std::filesystem::path& screenshot,
                                                      std::string& why_not);

// MikkTSpace tangents of triangles given corner by corner (3 positions, 3 normals, 2 UVs a corner, as
// floats), by three.js's port of the reference (tests/runtime/mikktspace.mjs): 4 floats a corner.
// Empty with `why_not` when the harness is not installed here; a failure throws.
std::optional<std::vector<float>> mikktspace_in_three(const std::filesystem::path& folder, const std::vector<float>& positions,
                                                      const std::vector<float>& normals, const std::vector<float>& texcoords,
                                                      std::string& why_not);

// The colour space three.js must give a texture read for `slot`: "srgb" for colour, "" for data.
std::string color_space_of_slot(const std::string& slot);

}  // namespace matbake::test

// In a test: what Chromium shows of `page`, or skip the test when it cannot run here.
#define MATBAKE_CHECK_PAGE_OR_SKIP(seen, page, screenshot)                                    \
  std::string seen##_why_not;                                                                  \
  const auto seen = ::matbake::test::check_page_in_chromium(page, screenshot, seen##_why_not); \
  if (!seen) GTEST_SKIP() << seen##_why_not

// In a test: `renders` for `models`, or skip the test when the runtime cannot run here.
#define MATBAKE_RENDER_OR_SKIP(renders, folder, models)                               \
  std::string renders##_why_not;                                                      \
  const auto renders = ::matbake::test::render_in_three(folder, models, renders##_why_not); \
  if (!renders) GTEST_SKIP() << renders##_why_not
