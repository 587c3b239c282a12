// `matbake bake` end to end: every Khronos model of ../shared baked from itself onto its 10%
// simplification (validator-clean, TANGENT on every baked primitive, equal to three.js's MikkTSpace
// port where the low-poly had none, per-vertex AO and curvature on every vertex), the bundled example baked onto itself (a flat normal map where
// the surfaces coincide: the 8-bit codes of (0, 0, 1)), and bad requests refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <functional>
#include <limits>
#include <numeric>
#include <set>

#include "lib/src/bake/frames.hpp"
#include "lib/src/gltf/document.hpp"
#include "lib/src/gltf/texture_files.hpp"
#include "matbake/bake.hpp"
#include "matbake/image.hpp"
#include "matbake/scene.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_builder.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/runtime.hpp"
#include "support/shapes.hpp"
#include "support/simplify.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
const fs::path kTestdata = fs::path(MATBAKE_TESTDATA_DIR) / "gltf";

// The model's .glb, else its .gltf; empty when it has neither.
fs::path model_file(const fs::path& folder) {
  for (const char* variant : {"glTF-Binary", "glTF"}) {
    if (!fs::is_directory(folder / variant)) continue;
    for (const auto& entry : fs::directory_iterator(folder / variant)) {
      const auto ext = entry.path().extension();
      if (ext == ".glb" || ext == ".gltf") return entry.path();
    }
  }
  return {};
}

// Instance k's corners (file order) as flat arrays for the MikkTSpace oracle, and the TANGENT the
// file gives each corner.
struct Corners {
  std::vector<float> positions, normals, texcoords, tangents;
};
Corners corners_of(const scene::Instance& inst, int texcoord) {
  Corners c;
  const std::vector<glm::vec3> normals = bake::corner_normals(inst);
  for (std::size_t t = 0; t < inst.triangles.size(); ++t) {
    const auto tri = bake::file_triangle(inst, t);
    for (std::size_t k = 0; k < 3; ++k) {
      const glm::vec3 p = inst.object.positions[tri[k]], n = normals[3 * t + bake::file_corner(inst, k)];
      const glm::vec2 uv = inst.texcoords[std::size_t(texcoord)][tri[k]];
      const glm::vec4 tangent = inst.object.tangents[tri[k]];
      c.positions.insert(c.positions.end(), {p.x, p.y, p.z});
      c.normals.insert(c.normals.end(), {n.x, n.y, n.z});
      c.texcoords.insert(c.texcoords.end(), {uv.x, uv.y});
      c.tangents.insert(c.tangents.end(), {tangent.x, tangent.y, tangent.z, tangent.w});
    }
  }
  return c;
}

TEST(CliBake, EveryKhronosModelOntoItsSimplificationIsValidatorCleanWithMikkTSpaceTangents) {
  if (!fs::is_directory(kTestdata)) GTEST_SKIP() << "no ../shared/testdata here (a newcomer's clone): nothing to bake";
  TempDir dir;
  std::size_t baked = 0, oracle_checks = 0;
  std::string oracle_why_not;
  for (const auto& entry : fs::directory_iterator(kTestdata)) {
    const fs::path high = model_file(entry.path());
    if (high.empty()) continue;
    const std::string name = entry.path().filename().string();
    const fs::path low = dir / (name + "_low.glb"), out = dir / (name + "_baked.glb");
    write_simplified(high, low, 0.1);
    const auto r = matbake({"--json", "bake", low.string(), "--from", high.string(), "-o", out.string(), "--size", "64",
                            "--texel-samples", "1", "--maps", "normal,ao,transfer", "--ao-samples", "4",
                            "--vertex-maps", "ao,curvature"});
    if (r.exit_code != 0) {  // a model without a material, or without UVs, has nothing to bake onto: said so
      EXPECT_TRUE(r.err.find("no primitive of the low-poly has a material") != std::string::npos ||
                  r.err.find("no material of the low-poly can take baked maps") != std::string::npos)
          << name << ": " << r.err;
      continue;
    }
    ++baked;
    MATBAKE_VALIDATE_OR_SKIP(report, out);
    EXPECT_EQ(report->errors, 0) << name << ": " << report->summary;
    for (const std::string& code : report->error_and_warning_codes) {
      EXPECT_EQ(code.find("TANGENT"), std::string::npos) << name << ": " << code;
    }
    auto before = scene::load_scene(low, {.texcoords = true, .object_space = true});
    auto after = scene::load_scene(out, {.texcoords = true, .object_space = true});
    ASSERT_TRUE(before && after) << name;
    ASSERT_EQ(before->instances.size(), after->instances.size()) << name;
    const auto echoed = nlohmann::json::parse(r.out);
    std::size_t vertices = 0;  // each placement's, all given _AO and _CURVATURE (the validator: as many as the rest)
    for (const scene::Instance& inst : before->instances) vertices += inst.positions.size();
    EXPECT_EQ(echoed["vertices"]["vertices"], vertices) << name;
    for (std::size_t k = 0; k < after->instances.size(); ++k) {
      const scene::Instance& inst = after->instances[k];
      if (inst.material < 0 || inst.texcoords.empty()) continue;
      ASSERT_EQ(inst.object.tangents.size(), inst.positions.size()) << name << " instance " << k << " has no TANGENT";
      if (!before->instances[k].object.tangents.empty()) continue;  // the file's own, kept
      int texcoord = 0;
      for (const auto& t : echoed["textures"]) {
        if (t["material"] == inst.material) texcoord = t["texcoord"];
      }
      const Corners c = corners_of(inst, texcoord);
      const auto oracle = mikktspace_in_three(dir.path(), c.positions, c.normals, c.texcoords, oracle_why_not);
      if (!oracle) continue;
      for (std::size_t i = 0; i < c.tangents.size(); ++i) {
        const float* o = &(*oracle)[i / 4 * 4];
        // Where MikkTSpace gives no direction (zero) the file holds a unit vector across the normal.
        if (i % 4 != 3 && o[0] == 0 && o[1] == 0 && o[2] == 0) continue;
        const float want = i % 4 == 3 ? -(*oracle)[i] : (*oracle)[i];  // glTF's sign is MikkTSpace's negated
        ASSERT_NEAR(c.tangents[i], want, 1e-4) << name << " instance " << k << " corner " << i / 4 << " component " << i % 4;
      }
      ++oracle_checks;
    }
  }
  EXPECT_GE(baked, 5u);
  if (oracle_checks == 0) GTEST_SKIP() << "tangents not compared with three.js's MikkTSpace: " << oracle_why_not;
}

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// A mesh baked onto itself through a cage of 0.1% of the scene: every ray's first hit is the point
// it started from, whose normal is the basis's own N, so each texel holds (0, 0, 1): codes 127 or
// 128 (½ on either side of float rounding), 255. Where another surface lies within the cage (its
// height not 0), it is skipped. The same bytes with one thread and with two.
TEST(CliBake, TheExampleOntoItselfGivesTheFlatNormalMapAndAoAndTheSameBytesForAnyJobs) {
  TempDir dir;
  const fs::path scene = kExamples / "showroom.gltf";
  const auto bake_with = [&](const std::string& jobs, const std::string& name) {
    return matbake({"--json", "--jobs", jobs, "bake", scene.string(), "--from", scene.string(), "-o", (dir / name).string(),
                    "--maps", "normal,height,ao,bent_normal", "--size", "64", "--texel-samples", "1", "--front", "0.001",
                    "--back", "0.001", "--ao-samples", "8"});
  };
  const auto r = bake_with("2", "self.gltf");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_FALSE(report["textures"].empty());
  std::size_t flat = 0, other = 0;
  for (const auto& t : report["textures"]) {
    EXPECT_EQ(t["misses"], 0) << t;
    const RawImage normal = read_raw(dir / t["files"][0].get<std::string>());
    const RawImage height = read_raw(t["files"][1].get<std::string>());
    ASSERT_EQ(normal.format, "uint8");
    ASSERT_EQ(normal.channels, 3);
    for (std::size_t texel = 0; texel < height.samples.size(); ++texel) {
      if (std::abs(height.samples[texel]) > 1e-6) {
        ++other;
        continue;
      }
      const double* code = &normal.samples[3 * texel];
      ASSERT_TRUE((code[0] == 127 || code[0] == 128) && (code[1] == 127 || code[1] == 128) && code[2] == 255)
          << t["name"] << " texel " << texel << ": " << code[0] << " " << code[1] << " " << code[2];
      ++flat;
    }
  }
  EXPECT_GT(flat, 20 * other);
  // AO is each material's occlusionTexture: its own 8-bit grey PNG.
  const auto written = nlohmann::json::parse(std::ifstream(dir / "self.gltf"));
  for (const auto& t : report["textures"]) {
    const auto& occlusion = written["materials"][t["material"].get<std::size_t>()]["occlusionTexture"];
    const auto& texture = written["textures"][occlusion["index"].get<std::size_t>()];
    EXPECT_EQ(written["images"][texture["source"].get<std::size_t>()]["uri"], t["files"][2]) << t["name"];
    const RawImage ao = read_raw(dir / t["files"][2].get<std::string>());
    EXPECT_TRUE(ao.format == "uint8" && ao.channels == 1) << t["name"];
  }
  fs::create_directories(dir / "one");
  fs::create_directories(dir / "two");
  const auto one = bake_with("1", "one/baked.glb"), two = bake_with("2", "two/baked.glb");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_TRUE(file_bytes(dir / "one/baked.glb") == file_bytes(dir / "two/baked.glb"));
  EXPECT_TRUE(file_bytes(dir / "one/baked_wood_height.exr") == file_bytes(dir / "two/baked_wood_height.exr"));
  EXPECT_TRUE(file_bytes(dir / "one/baked_wood_bent_normal.exr") == file_bytes(dir / "two/baked_wood_bent_normal.exr"));
}

// high.gltf: a smooth icosphere of `fine` subdivisions (normals radial); low.gltf: a flat-shaded
// one of `coarse`, each triangle its own UV island.
void write_icosphere_pair(const fs::path& folder, int fine, int coarse) {
  const Icosphere high = icosphere(fine);
  write_grey_mesh(folder / "high.gltf", high.vertices, high.vertices, {}, high.triangles);
  const AtlasMesh low = icosphere_atlas(coarse, true);
  write_grey_mesh(folder / "low.gltf", low.positions, low.normals, low.texcoords, low.triangles);
}

// `folder`/`from` rewritten as `to` by `edit` (its JSON; the buffers stay beside it).
void edit_gltf(const fs::path& folder, const std::string& from, const std::string& to,
               const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(folder / from));
  edit(j);
  std::ofstream(folder / to) << j.dump();
}

// The scene's nodes under one root node of `root`'s transform (a high-poly in other units, moved).
std::function<void(nlohmann::json&)> under_root(const nlohmann::json& root) {
  return [root](nlohmann::json& j) {
    nlohmann::json node = root;
    node["children"] = j["scenes"][0]["nodes"];
    j["nodes"].push_back(node);
    j["scenes"][0]["nodes"] = {j["nodes"].size() - 1};
  };
}

// A bake that cannot be right fails with one line naming the material, the share and the likely
// cause, and writes nothing: the high-poly in centimetres (×100), the high-poly moved away. Below
// max_misses, misses are a warning (stderr and --json) naming the cage reach that would meet them.
// A low-poly without a material, without UVs, and the two files swapped are three different errors.
TEST(CliBake, AUnitsOrPlacementMistakeFailsNamingTheCauseAndMissesBelowTheLimitWarn) {
  TempDir dir;
  write_icosphere_pair(dir.path(), 3, 1);
  edit_gltf(dir.path(), "high.gltf", "high_cm.gltf", under_root({{"scale", {100, 100, 100}}}));
  edit_gltf(dir.path(), "high.gltf", "high_moved.gltf", under_root({{"translation", {30, 0, 0}}}));
  const std::string low = (dir / "low.gltf").string(), out = (dir / "out.glb").string();
  const auto bake_from = [&](const std::string& high, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"bake", low, "--from", (dir / high).string(), "-o", out, "--size", "32"};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  auto r = bake_from("high_cm.gltf");
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, low, "material 0 '");
  EXPECT_NE(r.err.find("100% of the rays"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("more than --max-misses 0.5 allows: the high-poly's bounding box is 100× the low-poly's: the two are "
                       "likely in different units"), std::string::npos) << r.err;
  r = bake_from("high_moved.gltf");
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, low, "material 0 '");
  EXPECT_NE(r.err.find("the two meshes' bounding boxes barely overlap"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  // A cage 0.001 out over flat faces inside the sphere: the rays at the faces' middles start
  // beneath it and miss. Allowed, they are one warning line naming the reach that would meet them.
  r = matbake({"--json", "bake", low, "--from", (dir / "high.gltf").string(), "-o", (dir / "allowed.glb").string(), "--size",
               "32", "--front", "0.001", "--back", "0.001", "--absolute-cage", "--max-misses", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  const std::size_t misses = report["textures"][0]["misses"], rays = report["textures"][0]["rays"];
  EXPECT_GT(misses, rays / 10);
  ASSERT_EQ(report["warnings"].size(), 1u) << report["warnings"];
  const std::string warning = report["warnings"][0];
  EXPECT_NE(warning.find("missed the high-poly"), std::string::npos) << warning;
  EXPECT_NE(warning.find("the cage is too small: front 0.0"), std::string::npos) << warning;
  EXPECT_EQ(r.err, "matbake: warning: " + warning + "\n");
  // The same misses over the default limit: the error, and no file.
  r = bake_from("high.gltf", {"--front", "0.001", "--back", "0.001", "--absolute-cage", "--max-misses", "0.05"});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, low, "material 0 '");
  EXPECT_NE(r.err.find("the cage is too small"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  // Swapped: the "low-poly" (the sphere, without UVs) is the denser of the two.
  r = matbake({"bake", (dir / "high.gltf").string(), "--from", low, "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, (dir / "high.gltf").string(), "the low-poly's materials lack their UV sets, and it has 1280 triangles, "
                                                         "more than the high-poly's 80: are the two swapped?");
  edit_gltf(dir.path(), "low.gltf", "no_uv.gltf", [](nlohmann::json& j) { j["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_0"); });
  r = matbake({"bake", (dir / "no_uv.gltf").string(), "--from", (dir / "high.gltf").string(), "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, (dir / "no_uv.gltf").string(), "no material of the low-poly can take baked maps: each needs its UV set");
  edit_gltf(dir.path(), "low.gltf", "no_material.gltf", [](nlohmann::json& j) { j["meshes"][0]["primitives"][0].erase("material"); });
  r = matbake({"bake", (dir / "no_material.gltf").string(), "--from", (dir / "high.gltf").string(), "-o", out});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, (dir / "no_material.gltf").string(), "no primitive of the low-poly has a material");
  EXPECT_FALSE(fs::exists(out));
}

// A plane over a tilted plane (z = 0.1x + 0.05y − 0.02 beneath the low-poly's [-1, 1]², every texel
// centre one ray): the normal is the tilted plane's everywhere and the height its z. At 16 bits the
// normal map's codes are within one 16-bit step of n = normalize(−0.1, −0.05, 1) (8 bits is 128×
// coarser); the height as a 16-bit PNG, decoded through its reported range, within one step of
// it; the mask all hits. green directx into the glTF is one error line; beside it (bent_normal), allowed.
TEST(CliBake, SixteenBitNormalsAndPngMapsHoldTheTiltedPlaneWithinOneStep) {
  TempDir dir;
  const std::vector<std::array<std::uint32_t, 3>> quad = {{0, 1, 2}, {0, 2, 3}};
  write_grey_mesh(dir / "low.gltf", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, std::vector<glm::dvec3>(4, {0, 0, 1}),
                  {{0, 1}, {1, 1}, {1, 0}, {0, 0}}, quad);
  const auto plane = [](double x, double y) { return 0.1 * x + 0.05 * y - 0.02; };
  const glm::dvec3 n = glm::normalize(glm::dvec3(-0.1, -0.05, 1));
  std::vector<glm::dvec3> corners;
  for (const auto& [x, y] : {std::pair{-2.0, -2.0}, {2.0, -2.0}, {2.0, 2.0}, {-2.0, 2.0}}) corners.emplace_back(x, y, plane(x, y));
  write_grey_mesh(dir / "high.gltf", corners, std::vector<glm::dvec3>(4, n), {}, quad);
  const auto bake_with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(),
                                  "-o", (dir / "out.gltf").string(), "--size", "32", "--texel-samples", "1", "--front", "0.5",
                                  "--back", "0.5", "--absolute-cage"};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  const auto r = bake_with({"--maps", "normal,height,mask", "--bits", "16", "--map-format", "png"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto t = nlohmann::json::parse(r.out)["textures"][0];
  const auto normal = image::read_image(dir / t["files"][0].get<std::string>(), color::Transfer::linear);
  const auto height = image::read_image(t["files"][1].get<std::string>(), color::Transfer::linear);
  const auto mask = image::read_image(t["files"][2].get<std::string>(), color::Transfer::linear);
  ASSERT_TRUE(normal && height && mask);
  ASSERT_EQ(normal->width * normal->height, 32 * 32);
  const double lo = t["ranges"][1][0], hi = t["ranges"][1][1], step = 1.0 / 65535;
  EXPECT_EQ(lo, -hi);
  for (int j = 0; j < 32; ++j) {
    for (int i = 0; i < 32; ++i) {
      const std::size_t texel = std::size_t(j * 32 + i);
      const double x = 2 * (i + 0.5) / 32 - 1, y = 1 - 2 * (j + 0.5) / 32;
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(normal->pixels[3 * texel + std::size_t(k)] * 2.0 - 1, n[k], 2 * step) << i << "," << j;
      ASSERT_NEAR(lo + height->pixels[texel] * (hi - lo), plane(x, y), (hi - lo) * step) << i << "," << j;
      for (int k = 0; k < 3; ++k) ASSERT_EQ(mask->pixels[3 * texel + std::size_t(k)], k == 0 ? 1.0f : 0.0f) << i << "," << j;
    }
  }
  const auto refused = bake_with({"--maps", "normal,height", "--green", "directx"});
  EXPECT_EQ(refused.exit_code, 2);
  expect_one_error_line(refused, "", "--green directx: a glTF's normalTexture is OpenGL's convention");
  const auto beside = bake_with({"--maps", "bent_normal", "--green", "directx", "--ao-samples", "4"});
  EXPECT_EQ(beside.exit_code, 0) << beside.err;
}

// A box of half-size `h` at the origin, 4 vertices a face (hard edges, face normals), each face's
// UVs the whole tile.
void write_box(const fs::path& path, double h) {
  std::vector<glm::dvec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      glm::dvec3 n(0), u(0), v(0);
      n[axis] = sign, u[(axis + 1) % 3] = 1, v[(axis + 2) % 3] = sign;  // u × v = n
      const auto first = std::uint32_t(positions.size());
      for (const auto& [a, b] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
        positions.push_back(h * (n + double(a) * u + double(b) * v));
        normals.push_back(n);
        uvs.emplace_back(float(a + 1) / 2, float(1 - b) / 2);
      }
      triangles.push_back({first, first + 1, first + 2});
      triangles.push_back({first, first + 2, first + 3});
    }
  }
  write_grey_mesh(path, positions, normals, uvs, triangles);
}

// The number after `key` in `text` ("front 0.0289 (" → 0.0289); NaN when absent.
double number_after(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key);
  return at == std::string::npos ? std::nan("") : std::stod(text.substr(at + key.size()));
}

// What a stranger's bakes found (issue 70's attack), each now refused or named rightly:
// - the front the error suggests for a hard-edged box (the averaged cage moves a face's middle
//   only 1/√3 of front along its normal at the corners' mean) makes the bake pass;
// - a flat low-poly under a plane 0.05 above: the cage, not "barely overlap";
// - a high-poly facing away (its winding flipped): named so;
// - UVs wholly outside the tile: a warning that the maps are fill values;
// - a map beside the glTF named as an image the low-poly brings along: one error line, nothing
//   written (it was overwritten by the copy, exit 0).
TEST(CliBake, StrangersBakesAreRefusedOrNamedRightly) {
  TempDir dir;
  write_box(dir / "box.gltf", 0.5);
  write_box(dir / "big_box.gltf", 0.55);
  const auto bake = [&](const std::string& low, const std::string& high, const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"bake", (dir / low).string(), "--from", (dir / high).string(), "-o", (dir / out).string(), "--size", "32"};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  auto r = bake("box.gltf", "big_box.gltf", "a.glb");
  EXPECT_EQ(r.exit_code, 1);
  const double front = number_after(r.err, "the cage is too small: front ");
  ASSERT_TRUE(front > 0) << r.err;
  r = bake("box.gltf", "big_box.gltf", "a.glb", {"--json", "--front", std::to_string(front * 1.01)});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto passed = nlohmann::json::parse(r.out)["textures"][0];
  EXPECT_LE(passed["misses"].get<double>(), 0.06 * passed["rays"].get<double>()) << passed;

  // A plane 0.05 under a plane: the cage, and the front it names works.
  const std::vector<std::array<std::uint32_t, 3>> quad = {{0, 1, 2}, {0, 2, 3}};
  const std::vector<glm::dvec3> up(4, {0, 0, 1});
  const std::vector<glm::vec2> tile = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  write_grey_mesh(dir / "plane.gltf", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, up, tile, quad);
  write_grey_mesh(dir / "above.gltf", {{-1, -1, 0.05}, {1, -1, 0.05}, {1, 1, 0.05}, {-1, 1, 0.05}}, up, {}, quad);
  r = bake("plane.gltf", "above.gltf", "b.glb");
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_NE(r.err.find("the cage is too small: front 0.0"), std::string::npos) << r.err;
  r = bake("plane.gltf", "above.gltf", "b.glb", {"--front", std::to_string(number_after(r.err, "front ") * 1.01)});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  write_grey_mesh(dir / "facing_down.gltf", {{-1, -1, -0.005}, {1, -1, -0.005}, {1, 1, -0.005}, {-1, 1, -0.005}}, {}, {},
                  {{0, 2, 1}, {0, 3, 2}});
  r = bake("plane.gltf", "facing_down.gltf", "c.glb");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("most missed rays met only the backs of high-poly faces"), std::string::npos) << r.err;

  // UVs one tile to the right: nothing of the tile is covered, and the warning says so.
  write_grey_mesh(dir / "moved.gltf", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, up, {{1, 1}, {2, 1}, {2, 0}, {1, 0}}, quad);
  r = bake("moved.gltf", "plane.gltf", "d.glb", {"--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["textures"][0]["rays"], 0);
  EXPECT_NE(r.err.find("none of its UVs covers the 0–1 tile (2 triangles outside it"), std::string::npos) << r.err;

  // An image of the low-poly, copied beside the output, named as a baked map: refused, nothing written.
  fs::create_directories(dir / "in");
  fs::create_directories(dir / "out");
  write_grey_mesh(dir / "in/low.gltf", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, up, tile, quad);
  image::Image grey = gltf::blank(2, 2, 3);
  image::WriteOptions png;
  png.type = image::SampleType::u8;
  ASSERT_TRUE(image::write_image(grey, dir / "in/a_grey_height.png", png));
  edit_gltf(dir / "in", "low.gltf", "low.gltf", [](nlohmann::json& j) {
    j["images"] = {{{"uri", "a_grey_height.png"}}};
    j["textures"] = {{{"source", 0}}};
    j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  });
  r = bake("in/low.gltf", "plane.gltf", "out/a.gltf", {"--maps", "normal,height", "--map-format", "png"});
  EXPECT_EQ(r.exit_code, 2);
  expect_one_error_line(r, (dir / "out/a_grey_height.png").string(), "is written twice");
  EXPECT_TRUE(fs::is_empty(dir / "out"));
}

// A bake removes what it leaves unused, as gltf-transform's prune would, and nothing else: the
// low-poly's material has a normal map and an occlusion map (one sampler each), and the file also
// holds a texture no material uses (its image and sampler too). Baking normal and ao replaces the
// two maps: their textures, images and samplers go (they stayed, the validator's UNUSED_OBJECT), the
// file's own unused texture stays as it came, and every texture and image left is the baked ones'
// or that one. Validator-clean.
TEST(CliBake, WhatTheBakeReplacedIsRemovedAndTheFilesOwnUnusedObjectsStay) {
  TempDir dir;
  write_icosphere_pair(dir.path(), 3, 1);
  image::Image grey = gltf::blank(4, 4, 3);
  image::WriteOptions png;
  png.type = image::SampleType::u8;
  for (const char* name : {"old_normal", "old_occlusion", "spare"}) {
    ASSERT_TRUE(image::write_image(grey, dir / (std::string(name) + ".png"), png));
  }
  auto file = nlohmann::json::parse(std::ifstream(dir / "low.gltf"));
  file["samplers"] = {{{"magFilter", 9729}}, {{"magFilter", 9728}}, {{"wrapS", 33071}}};
  file["images"] = {{{"uri", "old_normal.png"}}, {{"uri", "old_occlusion.png"}}, {{"uri", "spare.png"}}};
  file["textures"] = {{{"source", 0}, {"sampler", 0}, {"name", "old normal"}},
                      {{"source", 1}, {"sampler", 1}, {"name", "old occlusion"}},
                      {{"source", 2}, {"sampler", 2}, {"name", "spare"}}};
  file["materials"][0]["normalTexture"] = {{"index", 0}};
  file["materials"][0]["occlusionTexture"] = {{"index", 1}};
  std::ofstream(dir / "low.gltf") << file.dump();
  fs::create_directories(dir / "out");
  const auto r = matbake({"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(), "-o",
                          (dir / "out" / "baked.gltf").string(), "--maps", "normal,ao", "--size", "64", "--front", "0.3",
                          "--back", "0.3", "--absolute-cage", "--ao-samples", "4"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  const auto written = nlohmann::json::parse(std::ifstream(dir / "out" / "baked.gltf"));
  std::set<std::string> texture_names, image_uris;
  for (const auto& t : written["textures"]) texture_names.insert(t.value("name", ""));
  for (const auto& i : written["images"]) image_uris.insert(i["uri"].get<std::string>());
  EXPECT_EQ(texture_names.count("old normal") + texture_names.count("old occlusion"), 0u) << written["textures"];
  EXPECT_EQ(texture_names.count("spare"), 1u);
  EXPECT_EQ(image_uris.count("spare.png"), 1u);
  EXPECT_EQ(image_uris.count("old_normal.png") + image_uris.count("old_occlusion.png"), 0u) << written["images"];
  EXPECT_EQ(written["textures"].size(), 3u);  // the baked normal map, the baked occlusion, spare
  EXPECT_EQ(written["images"].size(), 3u);
  const auto& material = written["materials"][0];
  const auto source = [&](const char* slot) {
    const auto& texture = written["textures"][material[slot]["index"].get<std::size_t>()];
    return written["images"][texture["source"].get<std::size_t>()]["uri"].get<std::string>();
  };
  EXPECT_EQ(source("normalTexture"), report["textures"][0]["files"][0]);
  EXPECT_EQ(source("occlusionTexture"), report["textures"][0]["files"][1]);
  // The spare texture kept its own image and sampler.
  for (const auto& t : written["textures"]) {
    if (t.value("name", "") != "spare") continue;
    EXPECT_EQ(written["images"][t["source"].get<std::size_t>()]["uri"], "spare.png");
    EXPECT_EQ(written["samplers"][t["sampler"].get<std::size_t>()], nlohmann::json({{"wrapS", 33071}}));
  }
  bool noted = false;
  for (const auto& note : report["notes"]) noted |= note.get<std::string>().starts_with("removed what the bake left unused: ");
  EXPECT_TRUE(noted) << report["notes"];
  MATBAKE_VALIDATE_OR_SKIP(validated, dir / "out" / "baked.gltf");
  EXPECT_EQ(validated->errors + validated->warnings, 0) << validated->summary;
}

// Per-vertex maps through the file. The low-poly: a 3 × 2 grid of the plane z = 0 over
// [−1, 1] × [0, 1] whose UVs mirror at x = 0 (u = |x|: its middle vertices need two tangents each,
// so the normal map splits them), with COLOR_0. The high-poly: the plane z = h(x, y) =
// 0.02 + 0.01 x + 0.005 y, to x = 1.5 where a wall stands. Every written vertex, the split copies
// too, holds h at its position as _HEIGHT (the extrusion's ray along −z meets the plane there), and
// the _AO of its original (same position); a bake with --vertex-ao-into COLOR_0 writes the file's
// colour times that AO (the same seed, the same rays). Tolerance: float32 at magnitude 1.
TEST(CliBake, VertexMapsAreAttributesThatSplitVerticesCarryAndColoursMultiply) {
  TempDir dir;
  const auto h = [](double x, double y) { return 0.02 + 0.01 * x + 0.005 * y; };
  {
    GltfBuilder b;
    std::vector<float> p, n, uv, colors;
    for (int row = 0; row < 2; ++row) {
      for (int col = 0; col < 3; ++col) {
        const float x = float(col - 1), y = float(row);
        p.insert(p.end(), {x, y, 0}), n.insert(n.end(), {0, 0, 1}), uv.insert(uv.end(), {std::abs(x), 1 - y});
        colors.insert(colors.end(), {(x + 1) / 2, 0.5f, 1 - y});
      }
    }
    const int mesh = b.add_mesh(b.add_vec3(p), b.add_indices({0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4}), 4, b.add_vec3(n));
    auto& primitive = b.doc["meshes"][0]["primitives"][0];
    primitive["attributes"]["TEXCOORD_0"] = b.add_floats(uv, "VEC2", 2);
    primitive["attributes"]["COLOR_0"] = b.add_floats(colors, "VEC3", 3);
    primitive["material"] = 0;
    b.doc["materials"] = {{{"name", "plane"}}};
    b.write(dir / "low.gltf", {b.add_node({{"mesh", mesh}})});
  }
  {
    GltfBuilder b;
    const std::vector<float> floor = {-3, -3, float(h(-3, -3)), 1.5f, -3, float(h(1.5, -3)), 1.5f, 3, float(h(1.5, 3)), -3, 3, float(h(-3, 3))};
    const std::vector<float> wall = {1.5f, -1e4f, -1, 1.5f, -1e4f, 1e4f, 1.5f, 1e4f, 1e4f, 1.5f, 1e4f, -1};
    const int a = b.add_mesh(b.add_vec3(floor), b.add_indices({0, 1, 2, 0, 2, 3}));
    const int c = b.add_mesh(b.add_vec3(wall), b.add_indices({0, 1, 2, 0, 2, 3}));
    b.write(dir / "high.gltf", {b.add_node({{"mesh", a}}), b.add_node({{"mesh", c}})});
  }
  const std::vector<std::string> common = {"bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(),
                                           "--front", "0.1", "--back", "0.1", "--absolute-cage", "--size", "16",
                                           "--ao-samples", "64", "--ao-max-distance", "100", "--ao-falloff", "none"};
  std::vector<std::string> with_normal = common, with_colour = common;
  with_normal.insert(with_normal.end(), {"--json", "--maps", "normal", "--vertex-maps", "height,ao", "-o", (dir / "a.glb").string()});
  with_colour.insert(with_colour.end(), {"--maps", "none", "--vertex-maps", "ao", "--vertex-ao-into", "COLOR_0", "-o", (dir / "b.glb").string()});
  const auto r = matbake(with_normal);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  EXPECT_GT(report["split_vertices"].get<int>(), 0) << "the mirrored UVs split no vertex: the test tests nothing";
  EXPECT_EQ(report["vertices"]["attributes"], nlohmann::json({"_HEIGHT", "_AO"}));
  const auto rc = matbake(with_colour);
  ASSERT_EQ(rc.exit_code, 0) << rc.err;
  MATBAKE_VALIDATE_OR_SKIP(validated, dir / "a.glb");
  EXPECT_EQ(validated->errors, 0) << validated->summary;

  const gltf::Document a = read_output(dir / "a.glb"), b = read_output(dir / "b.glb");
  const auto& attributes = a.json["meshes"][0]["primitives"][0]["attributes"];
  const std::vector<float> positions = float_accessor(a, attributes["POSITION"]), height = float_accessor(a, attributes["_HEIGHT"]);
  const std::vector<float> ao = float_accessor(a, attributes["_AO"]);
  const std::vector<float> colored = float_accessor(b, b.json["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"]);
  ASSERT_EQ(height.size(), positions.size() / 3);
  ASSERT_GT(height.size(), 6u);
  ASSERT_EQ(colored.size(), 6u * 3);
  double least_ao = 1;
  for (std::size_t v = 0; v < height.size(); ++v) {
    const float x = positions[3 * v], y = positions[3 * v + 1];
    EXPECT_NEAR(height[v], h(x, y), 1e-6) << "vertex " << v;
    const std::size_t original = std::size_t(y) * 3 + std::size_t(x + 1);  // the grid vertex at (x, y)
    EXPECT_EQ(ao[v], ao[original]) << "vertex " << v;
    least_ao = std::min(least_ao, double(ao[v]));
    if (v >= 6) continue;
    const float colour[3] = {(x + 1) / 2, 0.5f, 1 - y};
    for (int k = 0; k < 3; ++k) EXPECT_EQ(colored[3 * v + std::size_t(k)], colour[k] * ao[v]) << "vertex " << v;
  }
  EXPECT_LT(least_ao, 0.9) << "the wall occludes nothing: the COLOR_0 check tests nothing";
}

// --per-instance: one quad mesh placed by nodes A (at the origin) and B (moved by 10 along x) over a
// high-poly plane at z = 0.02 under A and 0.05 under B. Each placement gets its own mesh and
// material copy, TANGENT on both, and its own maps: every texel of A's height map and every
// _HEIGHT of A's vertices 0.02, B's 0.05. Without it, one texture and one set of vertices hold
// the placements' mean, 0.035. Tolerance: float32 at magnitude 10.
// The quad z = 0 over [−1, 1]² (normals +z, u along x, v against y) with material `material`, placed
// by each of `nodes` (a node's name, transform, ...), written to `path`.
void write_quad_low(const fs::path& path, const std::string& material, const std::vector<nlohmann::json>& nodes) {
  GltfBuilder b;
  const int quad = b.add_mesh(b.add_vec3({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}), b.add_indices({0, 1, 2, 0, 2, 3}), 4,
                              b.add_vec3({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
  auto& primitive = b.doc["meshes"][0]["primitives"][0];
  primitive["attributes"]["TEXCOORD_0"] = b.add_floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  primitive["material"] = 0;
  b.doc["materials"] = {{{"name", material}}};
  std::vector<int> placed;
  for (nlohmann::json node : nodes) {
    node["mesh"] = quad;
    placed.push_back(b.add_node(node));
  }
  b.write(path, placed);
}

TEST(CliBake, PerInstanceGivesEachPlacementItsOwnMapsAndVertexValues) {
  TempDir dir;
  write_quad_low(dir / "low.gltf", "quad", {{{"name", "A"}}, {{"name", "B"}, {"translation", {10, 0, 0}}}});
  {
    GltfBuilder b;
    const int a = b.add_mesh(b.add_vec3({-2, -2, 0.02f, 2, -2, 0.02f, 2, 2, 0.02f, -2, 2, 0.02f}), b.add_indices({0, 1, 2, 0, 2, 3}));
    const int c = b.add_mesh(b.add_vec3({8, -2, 0.05f, 12, -2, 0.05f, 12, 2, 0.05f, 8, 2, 0.05f}), b.add_indices({0, 1, 2, 0, 2, 3}));
    b.write(dir / "high.gltf", {b.add_node({{"mesh", a}}), b.add_node({{"mesh", c}})});
  }
  for (const bool per_instance : {true, false}) {
    const fs::path out = dir / (per_instance ? "each.gltf" : "mean.gltf");
    std::vector<std::string> args = {"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(),
                                     "--maps", "normal,height", "--vertex-maps", "height", "--front", "0.1", "--back", "0.1",
                                     "--absolute-cage", "--size", "8", "-o", out.string()};
    if (per_instance) args.push_back("--per-instance");
    const auto r = matbake(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    MATBAKE_VALIDATE_OR_SKIP(validated, out);
    EXPECT_EQ(validated->errors, 0) << validated->summary;
    const auto report = nlohmann::json::parse(r.out);
    const gltf::Document doc = read_output(out);
    ASSERT_EQ(report["textures"].size(), per_instance ? 2u : 1u);
    for (const auto& t : report["textures"]) {
      const std::string name = t["name"];
      const double want = !per_instance ? 0.035 : name == "quad" ? 0.02 : 0.05;
      EXPECT_EQ(t.value("copy_of_material", -1), per_instance && name != "quad" ? 0 : -1) << name;
      auto height = image::read_image(t["files"][1].get<std::string>(), color::Transfer::linear);
      ASSERT_TRUE(height) << name;
      for (float v : height->pixels) ASSERT_NEAR(v, want, 1e-6) << name;
    }
    for (const auto& node : doc.json["nodes"]) {
      const auto& attributes = doc.json["meshes"][node["mesh"].get<std::size_t>()]["primitives"][0]["attributes"];
      EXPECT_TRUE(attributes.contains("TANGENT")) << node["name"];
      const double want = !per_instance ? 0.035 : node["name"] == "A" ? 0.02 : 0.05;
      for (float v : float_accessor(doc, attributes["_HEIGHT"])) EXPECT_NEAR(v, want, 1e-6) << node["name"];
    }
    EXPECT_EQ(doc.json["meshes"].size(), per_instance ? 2u : 1u);
  }
}

// --udim: one primitive of two quads with material "stone", A over x in [−1, 0] with its UVs in
// tile 1001 and B over [0, 1] with its UVs in tile 1002 (u = x + 1 for both, v against y), over
// the tilted plane z = 0.1x + 0.05y − 0.02. Each tile's height map is that plane over its own quad
// (two different fields: tile 1001's x = u − 1, 1002's x = u), every texel within float rounding;
// the files are named <stem>_<material>_<map>.<tile>. In the glTF each tile is a material of its
// own ("stone", "stone (1002)"), the primitive split so that each holds its tile's triangles and
// its material's normalTexture the tile's image: validator-clean. A triangle across the tiles'
// border is one error line and writes nothing; without --udim, B is outside the 0–1 tile.
// `nan_triangle`: a third triangle (off to the side) whose UVs are NaN.
void write_udim_low(const fs::path& path, double b_u0, const std::string& material = "stone", bool nan_triangle = false) {
  GltfBuilder b;
  std::vector<float> xyz = {-1, -1, 0, 0, -1, 0, 0, 1, 0, -1, 1, 0, 0, -1, 0, 1, -1, 0, 1, 1, 0, 0, 1, 0};
  const auto u = [&](double x) { return float(x); };
  std::vector<float> uv = {u(0), 1, u(1), 1, u(1), 0, u(0), 0, u(b_u0), 1, u(b_u0 + 1), 1, u(b_u0 + 1), 0, u(b_u0), 0};
  std::vector<std::uint32_t> indices = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  if (nan_triangle) {
    xyz.insert(xyz.end(), {1.5f, -1, 0, 1.9f, -1, 0, 1.5f, -0.5f, 0});
    for (int k = 0; k < 6; ++k) uv.push_back(std::numeric_limits<float>::quiet_NaN());
    indices.insert(indices.end(), {8, 9, 10});
  }
  std::vector<float> normals;
  for (std::size_t v = 0; v < xyz.size() / 3; ++v) normals.insert(normals.end(), {0, 0, 1});
  const int mesh = b.add_mesh(b.add_vec3(xyz), b.add_indices(indices), 4, b.add_vec3(normals));
  auto& primitive = b.doc["meshes"][std::size_t(mesh)]["primitives"][0];
  primitive["attributes"]["TEXCOORD_0"] = b.add_floats(uv, "VEC2", 2);
  primitive["material"] = 0;
  b.doc["materials"] = {{{"name", material}}};
  b.write(path, {b.add_node({{"mesh", mesh}})});
}

TEST(CliBake, UdimTilesEachHoldTheirOwnFieldAndTheGltfTakesOneMaterialPerTile) {
  TempDir dir;
  write_udim_low(dir / "low.gltf", 1);
  const auto plane = [](double x, double y) { return 0.1 * x + 0.05 * y - 0.02; };
  const glm::dvec3 n = glm::normalize(glm::dvec3(-0.1, -0.05, 1));
  std::vector<glm::dvec3> corners;
  for (const auto& [x, y] : {std::pair{-2.0, -2.0}, {2.0, -2.0}, {2.0, 2.0}, {-2.0, 2.0}}) corners.emplace_back(x, y, plane(x, y));
  write_grey_mesh(dir / "high.gltf", corners, std::vector<glm::dvec3>(4, n), {}, {{0, 1, 2}, {0, 2, 3}});
  const auto bake_with = [&](const std::string& out, std::vector<std::string> extra) {
    std::vector<std::string> args{"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(), "-o",
                                  (dir / out).string(), "--maps", "normal,height", "--size", "16", "--texel-samples", "1",
                                  "--front", "0.5", "--back", "0.5", "--absolute-cage"};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  const auto r = bake_with("out.gltf", {"--udim"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["textures"].size(), 2u) << report.dump(1);
  const gltf::Document doc = read_output(dir / "out.gltf");
  for (const auto& t : report["textures"]) {
    const int tile = t.value("tile", 0);
    ASSERT_TRUE(tile == 1001 || tile == 1002) << t.dump();
    EXPECT_EQ(t["name"], tile == 1001 ? "stone" : "stone (1002)");
    EXPECT_EQ(t["files"][0], "out_stone_normal." + std::to_string(tile) + ".png");
    EXPECT_EQ(fs::path(t["files"][1].get<std::string>()), dir / ("out_stone_height." + std::to_string(tile) + ".exr"));
    const auto height = image::read_image(t["files"][1].get<std::string>(), color::Transfer::linear);
    ASSERT_TRUE(height);
    for (int j = 0; j < 16; ++j) {
      for (int i = 0; i < 16; ++i) {
        const double u = (i + 0.5) / 16, x = tile == 1001 ? u - 1 : u, y = 1 - 2 * (j + 0.5) / 16;
        ASSERT_NEAR(height->pixels[std::size_t(j * 16 + i)], plane(x, y), 1e-6) << tile << ": " << i << "," << j;
      }
    }
    // The material of the tile: its normalTexture is the tile's image.
    const auto& material = doc.json["materials"][t["material"].get<std::size_t>()];
    const int texture = material["normalTexture"]["index"];
    const int image = doc.json["textures"][std::size_t(texture)]["source"];
    EXPECT_EQ(doc.json["images"][std::size_t(image)]["uri"], t["files"][0]);
  }
  // Each primitive's triangles lie in its material's tile: A's vertices (x ≤ 0) with "stone".
  const auto& primitives = doc.json["meshes"][0]["primitives"];
  ASSERT_EQ(primitives.size(), 2u);
  for (const auto& primitive : primitives) {
    const std::string material = doc.json["materials"][primitive["material"].get<std::size_t>()]["name"];
    const std::vector<float> position = float_accessor(doc, primitive["attributes"]["POSITION"]);
    auto indices = gltf::accessor_bytes(doc, primitive["indices"].get<std::size_t>());
    ASSERT_TRUE(indices);
    EXPECT_EQ(indices->count, 6u) << material;
    for (std::size_t k = 0; k < indices->count; ++k) {
      const std::uint32_t v = gltf::index_value(indices->first + k * indices->stride, indices->component_type);
      const float x = position[3 * v], mid = material == "stone" ? -0.5f : 0.5f;
      EXPECT_LE(std::abs(x - mid), 0.5f) << material << " vertex " << v;
    }
    EXPECT_TRUE(primitive["attributes"].contains("TANGENT"));
  }
  MATBAKE_VALIDATE_OR_SKIP(validated, dir / "out.gltf");
  EXPECT_EQ(validated->errors, 0) << validated->summary;

  // Across an inner border (B's UVs from u = 0.5 to 1.5), and across the tiles' outer edge (from
  // −0.8 to 0.2: triangle 2's centroid lies outside every tile, a corner inside tile 1001).
  for (const double b_u0 : {0.5, -0.8}) {
    write_udim_low(dir / "across.gltf", b_u0);
    const auto across = matbake({"bake", (dir / "across.gltf").string(), "--from", (dir / "high.gltf").string(), "-o",
                                 (dir / "across_out.gltf").string(), "--size", "16", "--udim"});
    EXPECT_EQ(across.exit_code, 1) << b_u0;
    expect_one_error_line(across, (dir / "across.gltf").string(),
                          "material 0 'stone': triangle 2 of mesh 0 primitive 0 lies across a UDIM tile's border");
    EXPECT_FALSE(fs::exists(dir / "across_out.gltf"));
  }

  // PNG maps beside: one range for a material's tiles (a UDIM set is read with one scale). A
  // triangle with NaN UVs: one note, not a warning per tile. A material name of 300 characters:
  // files named for its first 64.
  write_udim_low(dir / "long.gltf", 1, std::string(300, 'x'), true);
  const auto png = matbake({"--json", "bake", (dir / "long.gltf").string(), "--from", (dir / "high.gltf").string(), "-o",
                            (dir / "png.gltf").string(), "--maps", "normal,height", "--size", "16", "--texel-samples", "1",
                            "--front", "0.5", "--back", "0.5", "--absolute-cage", "--udim", "--map-format", "png"});
  ASSERT_EQ(png.exit_code, 0) << png.err;
  EXPECT_EQ(png.err, "");
  const auto png_report = nlohmann::json::parse(png.out);
  ASSERT_EQ(png_report["textures"].size(), 2u);
  EXPECT_EQ(png_report["textures"][0]["ranges"][1], png_report["textures"][1]["ranges"][1]);
  // The largest |height|: tile 1001's, near (−1, −1), where the plane is −0.17 (tile 1002's alone: 0.13).
  EXPECT_NEAR(png_report["textures"][1]["ranges"][1][1].get<double>(), 0.17, 0.01);
  EXPECT_EQ(png_report["textures"][0]["files"][0], "png_" + std::string(64, 'x') + "_normal.1001.png");
  EXPECT_NE(png_report["notes"].dump().find("1 triangles lie outside the UDIM tiles"), std::string::npos) << png_report["notes"].dump();

  const auto one_tile = bake_with("plain.gltf", {});
  ASSERT_EQ(one_tile.exit_code, 0) << one_tile.err;
  const auto plain = nlohmann::json::parse(one_tile.out);
  EXPECT_EQ(plain["textures"].size(), 1u);
  EXPECT_FALSE(plain["textures"][0].contains("tile"));
  EXPECT_EQ(plain["textures"][0]["outside_tile"], 2);
}

// Matching parts by name from the files' node names: the low-poly's quad (node "plate_low") under
// two high-poly parts within its cage, its own 0.02 below it ("plate_high") and another's 0.02
// above it ("bolt_high"). Every ray meets the bolt first; with --match by_name, only the plate.
// Renamed so that no high part matches, every texel misses and the notes name the part.
// Khronos NormalTangentMirrorTest (mirrored UVs: its two halves share one normal map, their
// TANGENTs' w opposite) baked onto itself with --high-normal-maps at half its normal map's 2048²:
// each texel centre lies where four of its texels meet, so the bake reads their mean code (the
// sampler is linear), and through the same tangent frame on either side it must give that back.
// Over every hit texel (the mask), mean and 99th-percentile angle to the decoded mean within the
// 8-bit step (0.45°); without the flag, the vertex normals' flat map is far from it. The file's
// normalTexture has no "scale" (its default), which once failed the flag with a JSON type error.
TEST(CliBake, AMirroredModelOntoItselfWithItsOwnNormalMapGivesThatMapBack) {
  const fs::path model = kTestdata / "NormalTangentMirrorTest/glTF-Binary/NormalTangentMirrorTest.glb";
  if (!fs::is_regular_file(model)) GTEST_SKIP() << "no ../shared/testdata here (a newcomer's clone): no mirrored model to bake";
  auto doc = gltf::read_document(model);
  ASSERT_TRUE(doc) << doc.error().message;
  const std::size_t normal_image = doc->json["textures"][doc->json["materials"][0]["normalTexture"]["index"].get<std::size_t>()]["source"];
  const auto bytes = gltf::image_bytes(*doc, normal_image);
  ASSERT_TRUE(bytes);
  const auto source = image::decode_image(std::span(reinterpret_cast<const unsigned char*>(bytes->data()), bytes->size()), "normal.png",
                                          color::Transfer::linear);
  ASSERT_TRUE(source);
  ASSERT_EQ(source->width, 2048);
  const int size = 1024, channels = source->channels;
  TempDir dir;
  const auto angles = [&](bool detail) {
    std::vector<std::string> args = {"--json", "bake", model.string(), "--from", model.string(), "-o", (dir / "out.gltf").string(),
                                     "--maps", "normal,mask", "--size", std::to_string(size), "--padding", "0"};
    if (detail) args.push_back("--high-normal-maps");
    const auto r = matbake(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const auto report = nlohmann::json::parse(r.out);
    auto baked = image::read_image(dir / report["textures"][0]["files"][0].get<std::string>(), color::Transfer::linear);
    auto mask = image::read_image(dir / report["textures"][0]["files"][1].get<std::string>(), color::Transfer::linear);
    EXPECT_TRUE(baked && mask);
    std::vector<double> out;
    for (int y = 0; baked && mask && y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const std::size_t t = std::size_t(y * size + x);
        if (mask->pixels[t * std::size_t(mask->channels)] != 1.0f) continue;  // red: every ray hit
        glm::dvec3 mean(0);
        for (int k = 0; k < 4; ++k) {
          const std::size_t s = (std::size_t(2 * y + k / 2) * 2048 + std::size_t(2 * x + k % 2)) * std::size_t(channels);
          mean += glm::dvec3(source->pixels[s], source->pixels[s + 1], source->pixels[s + 2]) / 4.0;
        }
        const float* b = &baked->pixels[t * std::size_t(baked->channels)];
        const glm::dvec3 want = glm::normalize(2.0 * mean - 1.0), got = glm::normalize(2.0 * glm::dvec3(b[0], b[1], b[2]) - 1.0);
        out.push_back(std::acos(std::clamp(glm::dot(want, got), -1.0, 1.0)) * 180.0 / M_PI);
      }
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  const std::vector<double> detail = angles(true), flat = angles(false);
  ASSERT_GT(detail.size(), 200000u);
  const auto mean = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / double(v.size()); };
  EXPECT_LT(mean(detail), 0.1);
  EXPECT_LT(detail[detail.size() * 99 / 100], 0.9);
  EXPECT_GT(mean(flat), 3.0);
}

TEST(CliBake, MatchByNameKeepsAPartsRaysOnItsOwnHighPolyPart) {
  TempDir dir;
  const auto write_low = [&](const std::string& name) { write_quad_low(dir / "low.gltf", "plate", {{{"name", name}}}); };
  {
    GltfBuilder b;
    const int below = b.add_mesh(b.add_vec3({-2, -2, -0.02f, 2, -2, -0.02f, 2, 2, -0.02f, -2, 2, -0.02f}), b.add_indices({0, 1, 2, 0, 2, 3}));
    const int above = b.add_mesh(b.add_vec3({-2, -2, 0.02f, 2, -2, 0.02f, 2, 2, 0.02f, -2, 2, 0.02f}), b.add_indices({0, 1, 2, 0, 2, 3}));
    b.write(dir / "high.gltf", {b.add_node({{"mesh", below}, {"name", "plate_high"}}), b.add_node({{"mesh", above}, {"name", "bolt_high"}})});
  }
  const fs::path out = dir / "out.gltf";
  const auto bake_with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(),
                                     "--maps", "height", "--front", "0.1", "--back", "0.1", "--absolute-cage", "--size", "8",
                                     "-o", out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  write_low("plate_low");
  for (const bool by_name : {false, true}) {
    const auto r = bake_with(by_name ? std::vector<std::string>{"--match", "by_name"} : std::vector<std::string>{});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto report = nlohmann::json::parse(r.out);
    auto height = image::read_image(report["textures"][0]["files"][0].get<std::string>(), color::Transfer::linear);
    ASSERT_TRUE(height);
    for (float v : height->pixels) ASSERT_NEAR(v, by_name ? -0.02 : 0.02, 1e-6) << by_name;
  }
  // Every ray a miss: the bake fails naming the part (not a flat map with exit 0); allowed, the
  // notes name it and every texel is filled.
  write_low("washer_low");
  fs::remove(out);
  auto r = bake_with({"--match", "by_name"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("material 0 'plate': 100% of the rays (256 of 256) missed the high-poly, more than --max-misses 0.5 "
                       "allows: no high-poly part matches the low-poly parts 'washer_low' by name"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  r = bake_with({"--match", "by_name", "--max-misses", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["textures"][0]["missed_texels"], report["textures"][0]["texels"]);
  EXPECT_NE(report["notes"].dump().find("no high-poly part matches these low-poly parts by name, so each of their rays misses: 'washer_low'"),
            std::string::npos) << report["notes"].dump();
}

// Cage distances per part (--front-by-part, --back-by-part; a manifest's tables): one quad placed
// as "plate_low" at the origin and as "bolt_low" 10 along x, each its own maps (--per-instance);
// plate_high lies 0.3 below the plate, bolt_high 0.4 above the bolt, the cage 0.1 either way. Each
// part's own reach (the plate's back 0.5, the bolt's front 0.5) meets its surface at every texel
// and vertex: heights −0.3 and 0.4 exactly (float32). Without them every ray misses (the error).
// A part name no low part has is one error line listing the parts, and so is a table without
// --match by_name.
TEST(CliBake, CageDistancesPerPartReachEachPartsOwnSurface) {
  TempDir dir;
  write_quad_low(dir / "low.gltf", "quad", {{{"name", "plate_low"}}, {{"name", "bolt_low"}, {"translation", {10, 0, 0}}}});
  {
    GltfBuilder b;
    const int plate = b.add_mesh(b.add_vec3({-2, -2, -0.3f, 2, -2, -0.3f, 2, 2, -0.3f, -2, 2, -0.3f}), b.add_indices({0, 1, 2, 0, 2, 3}));
    const int bolt = b.add_mesh(b.add_vec3({8, -2, 0.4f, 12, -2, 0.4f, 12, 2, 0.4f, 8, 2, 0.4f}), b.add_indices({0, 1, 2, 0, 2, 3}));
    b.write(dir / "high.gltf", {b.add_node({{"mesh", plate}, {"name", "plate_high"}}), b.add_node({{"mesh", bolt}, {"name", "bolt_high"}})});
  }
  const fs::path out = dir / "out.gltf";
  const auto bake_with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(),
                                     "--maps", "height", "--vertex-maps", "height", "--front", "0.1", "--back", "0.1",
                                     "--absolute-cage", "--size", "8", "--per-instance", "-o", out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  const auto r = bake_with({"--match", "by_name", "--front-by-part", "bolt=0.5", "--back-by-part", "plate=0.5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["textures"].size(), 2u);
  for (const auto& t : report["textures"]) {
    const double want = t["name"] == "quad" ? -0.3 : 0.4;  // the plate keeps the material, the bolt a copy
    EXPECT_EQ(t["misses"], 0) << t["name"];
    auto height = image::read_image(t["files"][0].get<std::string>(), color::Transfer::linear);
    ASSERT_TRUE(height);
    for (float v : height->pixels) ASSERT_NEAR(v, want, 1e-6) << t["name"];
  }
  const gltf::Document doc = read_output(out);
  for (const auto& node : doc.json["nodes"]) {
    const auto& attributes = doc.json["meshes"][node["mesh"].get<std::size_t>()]["primitives"][0]["attributes"];
    for (float v : float_accessor(doc, attributes["_HEIGHT"])) EXPECT_NEAR(v, node["name"] == "plate_low" ? -0.3 : 0.4, 1e-6);
  }
  fs::remove(out);
  auto failed = bake_with({"--match", "by_name"});
  EXPECT_EQ(failed.exit_code, 1);
  EXPECT_NE(failed.err.find("100% of the rays"), std::string::npos) << failed.err;
  failed = bake_with({"--match", "by_name", "--front-by-part", "blot=0.5"});
  EXPECT_EQ(failed.exit_code, 2);
  expect_one_error_line(failed, "", "--front-by-part names part 'blot', which no low-poly part is called (its parts: 'bolt', 'plate')");
  failed = bake_with({"--front-by-part", "bolt=0.5"});
  EXPECT_EQ(failed.exit_code, 2);
  EXPECT_NE(failed.err.find("--front-by-part"), std::string::npos) << failed.err;
  EXPECT_NE(failed.err.find("--match by_name"), std::string::npos) << failed.err;
  failed = bake_with({"--match", "by_name", "--back-by-part", "bolt=-1"});
  EXPECT_EQ(failed.exit_code, 2);
  expect_one_error_line(failed, "", "--back-by-part: 'bolt=-1': part=distance pairs");
  // A cage far beyond the meshes (a part's, or the whole cage's): refused, where Embree aborted
  // (exit 134) on rays starting 1e30 away.
  const std::vector<std::string> whole = {"bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(),
                                          "-o", out.string(), "--front", "1e19", "--absolute-cage"};
  for (const RunResult& deep : {bake_with({"--match", "by_name", "--front-by-part", "bolt=1e30"}), matbake(whole)}) {
    failed = deep;
    EXPECT_EQ(failed.exit_code, 2);
    expect_one_error_line(failed, "", "the cage reaches ");
  }
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliBake, BadRequestsAreOneErrorLineAndWriteNothing) {
  TempDir dir;
  const fs::path scene = kExamples / "showroom.gltf";
  const std::string out = (dir / "out.glb").string();
  const auto bake_args = [&](std::vector<std::string> extra) {
    std::vector<std::string> args{"bake", scene.string(), "--from", scene.string(), "-o", out};
    args.insert(args.end(), extra.begin(), extra.end());
    return matbake(args);
  };
  auto r = bake_args({"--maps", "normal,shiny"});
  EXPECT_EQ(r.exit_code, 2);
  expect_one_error_line(r, "", "--maps: 'normal,shiny': maps among " + names_in(bake::kMapNames) + ", comma-separated");
  r = bake_args({"--maps", "normal,normal"});
  expect_one_error_line(r, "", "--maps: 'normal,normal': each map once");
  r = bake_args({"--match", "sometimes"});
  EXPECT_EQ(r.exit_code, 2);
  expect_one_error_line(r, "", "--match: 'sometimes': use always or by_name");
  r = bake_args({"--front", "0", "--back", "0"});
  EXPECT_EQ(r.exit_code, 2);
  expect_one_error_line(r, "", "the cage distances must be finite, 0 or more, and not both 0");
  r = matbake({"bake", scene.string(), "--from", (dir / "missing.glb").string(), "-o", out});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find((dir / "missing.glb").string()), std::string::npos) << r.err;
  r = matbake({"bake", scene.string(), "--from", scene.string(), "-o", scene.string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("showroom.gltf"), std::string::npos) << r.err;
  // A cage that is not the low-poly with its vertices moved; one that is the output.
  TempDir other;
  write_grey_mesh(other / "quad.gltf", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {}, {}, {{0, 1, 2}});
  r = bake_args({"--cage", (other / "quad.gltf").string()});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, (other / "quad.gltf").string(), "cannot be the low-poly's cage: it places 1 primitives where the low-poly places");
  r = bake_args({"--cage", out});
  EXPECT_EQ(r.exit_code, 2);  // the output named as an input: a usage error, as -o naming the low-poly
  EXPECT_NE(r.err.find(out), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// What a runtime shows: a smooth sphere of 5120 triangles baked onto a flat-shaded icosphere of 320,
// rendered by three.js in Chromium beside the sphere itself. The baked normal map must bring the
// icosphere's render closer to the sphere's than the bare icosphere is, in every view, and closer
// than the same bake stored in the other green convention (what a runtime shows when the basis or
// its sign is wrong).
TEST(CliBake, ABakedIcosphereRendersInThreeJsCloserToTheSphereThanItself) {
  TempDir dir;
  write_icosphere_pair(dir.path(), 4, 2);
  const auto r = matbake({"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(), "-o",
                          (dir / "opengl.gltf").string(), "--size", "512", "--front", "0.3", "--back", "0.3", "--absolute-cage"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The other convention (matbake refuses to write it into a glTF): the same file with the normal
  // map's green flipped, 255 − code.
  const std::string normal = nlohmann::json::parse(r.out)["textures"][0]["files"][0];
  auto map = image::read_image(dir / normal, color::Transfer::linear);
  ASSERT_TRUE(map) << map.error().to_string();
  for (std::size_t i = 1; i < map->pixels.size(); i += std::size_t(map->channels)) map->pixels[i] = 1.0f - map->pixels[i];
  image::WriteOptions png;
  png.type = image::SampleType::u8;
  ASSERT_TRUE(image::write_image(*map, dir / "flipped.png", png));
  std::string text = read_bytes(dir / "opengl.gltf");
  text.replace(text.find("\"" + normal + "\""), normal.size() + 2, "\"flipped.png\"");
  write_bytes(dir / "directx.gltf", text);
  std::string why_not;
  const auto rendered = render_in_three(dir.path(), {{"high", dir / "high.gltf"}, {"low", dir / "low.gltf"},
                                                     {"baked", dir / "opengl.gltf"}, {"flipped", dir / "directx.gltf"}},
                                        why_not);
  if (!rendered) GTEST_SKIP() << why_not;
  for (const auto& [name, model] : *rendered) EXPECT_TRUE(model.console.empty()) << name << ": " << model.console.front();
  for (const std::string& view : kRuntimeViews) {
    const auto psnr = [&](const char* name) { return render_psnr(rendered->at("high").renders.at(view), rendered->at(name).renders.at(view)); };
    const double bare = psnr("low"), baked = psnr("baked"), flipped = psnr("flipped");
    RecordProperty("psnr_" + view, std::to_string(bare) + " bare, " + std::to_string(baked) + " baked, " + std::to_string(flipped) + " flipped");
    std::printf("%s: bare %.2f dB, baked %.2f dB, flipped green %.2f dB\n", view.c_str(), bare, baked, flipped);
    EXPECT_GT(baked, bare) << view;
    EXPECT_GT(baked, flipped) << view;
  }
}

// A UDIM bake as a runtime shows it: the icosphere pair above with the islands of the triangles
// on the +x side moved to tile 1002 (u + 1), baked with --udim, rendered by three.js beside the
// sphere. Each tile's material samples its own image at the file's UVs past 0–1 (the default
// sampler repeats), so the render must come closer to the sphere's than the bare icosphere in
// every view, and closer than the same file with tile 1002's material reading tile 1001's image
// (what a runtime shows where a tile takes the wrong image).
TEST(CliBake, AUdimBakeRendersInThreeJsWithEachTilesOwnImage) {
  TempDir dir;
  const Icosphere high = icosphere(4);
  write_grey_mesh(dir / "high.gltf", high.vertices, high.vertices, {}, high.triangles);
  AtlasMesh low = icosphere_atlas(2, true);
  for (std::size_t t = 0; t < low.triangles.size(); ++t) {
    const auto& c = low.triangles[t];
    if (low.positions[c[0]].x + low.positions[c[1]].x + low.positions[c[2]].x <= 0) continue;
    for (std::uint32_t v : c) low.texcoords[v].x += 1;  // corners are not shared (one island a triangle)
  }
  write_grey_mesh(dir / "low.gltf", low.positions, low.normals, low.texcoords, low.triangles);
  const auto r = matbake({"--json", "bake", (dir / "low.gltf").string(), "--from", (dir / "high.gltf").string(), "-o",
                          (dir / "udim.gltf").string(), "--size", "512", "--front", "0.3", "--back", "0.3", "--absolute-cage", "--udim"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto textures = nlohmann::json::parse(r.out)["textures"];
  ASSERT_EQ(textures.size(), 2u);
  const std::string first = textures[0]["files"][0], second = textures[1]["files"][0];
  std::string text = read_bytes(dir / "udim.gltf");
  text.replace(text.find("\"" + second + "\""), second.size() + 2, "\"" + first + "\"");
  write_bytes(dir / "wrong.gltf", text);
  std::string why_not;
  const auto rendered = render_in_three(dir.path(), {{"high", dir / "high.gltf"}, {"low", dir / "low.gltf"},
                                                     {"udim", dir / "udim.gltf"}, {"wrong", dir / "wrong.gltf"}},
                                        why_not);
  if (!rendered) GTEST_SKIP() << why_not;
  for (const auto& [name, model] : *rendered) EXPECT_TRUE(model.console.empty()) << name << ": " << model.console.front();
  for (const std::string& view : kRuntimeViews) {
    const auto psnr = [&](const char* name) { return render_psnr(rendered->at("high").renders.at(view), rendered->at(name).renders.at(view)); };
    const double bare = psnr("low"), udim = psnr("udim"), wrong = psnr("wrong");
    RecordProperty("psnr_" + view, std::to_string(bare) + " bare, " + std::to_string(udim) + " udim, " + std::to_string(wrong) + " wrong");
    std::printf("%s: bare %.2f dB, udim %.2f dB, tile 1002 with 1001's image %.2f dB\n", view.c_str(), bare, udim, wrong);
    EXPECT_GT(udim, bare) << view;
    EXPECT_GT(udim, wrong) << view;
  }
}

}  // namespace
}  // namespace matbake::test
