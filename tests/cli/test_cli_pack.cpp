// `matbake pack`, `unpack` and `workflow` end to end: every 8-bit code through pack and unpack,
// preset channels read back from the files, bad inputs, and the workflow report.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

// 256×1 maps whose texel i holds different codes in every channel, all 256 codes in each.
void write_code_sources(const fs::path& dir) {
  std::vector<double> kd, ks, mask, gloss;
  for (int i = 0; i < 256; ++i) {
    kd.insert(kd.end(), {double(i), double(255 - i), double((i * 7) % 256)});
    ks.insert(ks.end(), {double((i * 5) % 256), double(i), double(255 - i)});
    mask.push_back((i * 3) % 256);
    gloss.push_back(i);
  }
  write_raw(dir / "kd.png", 256, 1, 3, "uint8", kd);
  write_raw(dir / "ks.png", 256, 1, 3, "uint8", ks);
  write_raw(dir / "mask.png", 256, 1, 1, "uint8", mask);
  write_raw(dir / "gloss.png", 256, 1, 1, "uint8", gloss);
}

std::vector<std::string> sources_from(const fs::path& dir) {
  return {"--kd", (dir / "kd.png").string(), "--ks", (dir / "ks.png").string(),
          "--mask", (dir / "mask.png").string(), "--gloss", (dir / "gloss.png").string()};
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

TEST(CliPack, EveryEightBitCodeSurvivesPackAndUnpack) {
  for (const char* transfer : {"srgb", "gamma2.2"}) {
    TempDir dir;
    write_code_sources(dir.path());
    const auto packed = matbake(concat({"pack", "--transfer", transfer, "-o", (dir / "A.png").string(), "-o",
                                        (dir / "B.png").string()},
                                       sources_from(dir.path())));
    ASSERT_EQ(packed.exit_code, 0) << packed.err;
    // The pair holds the sources' codes: colour encoded with the same curve, alpha as stored.
    const RawImage a = read_raw(dir / "A.png"), b = read_raw(dir / "B.png"), kd = read_raw(dir / "kd.png");
    ASSERT_EQ(a.channels, 4);
    for (int i = 0; i < 256; ++i) {
      EXPECT_EQ(a.samples[i * 4 + 0], kd.samples[i * 3 + 0]) << transfer << " " << i;
      EXPECT_EQ(a.samples[i * 4 + 2], kd.samples[i * 3 + 2]) << transfer << " " << i;
      EXPECT_EQ(a.samples[i * 4 + 3], (i * 3) % 256);
      EXPECT_EQ(b.samples[i * 4 + 3], i);
    }
    // unpack ∘ pack = identity on the sources' codes.
    const auto unpacked = matbake({"unpack", "--transfer", transfer, (dir / "A.png").string(),
                                   (dir / "B.png").string(), "-o", (dir / "back").string()});
    ASSERT_EQ(unpacked.exit_code, 0) << unpacked.err;
    for (const char* name : {"kd.png", "ks.png", "mask.png", "gloss.png"}) {
      EXPECT_EQ(read_raw(dir / "back" / name).samples, read_raw(dir / name).samples) << transfer << " " << name;
    }
    // pack ∘ unpack = identity on the pair's codes.
    const auto repacked = matbake(concat({"pack", "--transfer", transfer, "-o", (dir / "A2.png").string(), "-o",
                                          (dir / "B2.png").string()},
                                         sources_from(dir / "back")));
    ASSERT_EQ(repacked.exit_code, 0) << repacked.err;
    EXPECT_EQ(read_raw(dir / "A2.png").samples, a.samples);
    EXPECT_EQ(read_raw(dir / "B2.png").samples, b.samples);
  }
}

TEST(CliPack, PresetChannelsInTheFiles) {
  TempDir dir;
  std::vector<double> roughness;
  for (int i = 0; i < 256; ++i) roughness.push_back(i);
  write_raw(dir / "roughness.png", 256, 1, 1, "uint8", roughness);
  const auto r = matbake({"pack", "--layout", "unity-hdrp", "--base-color", "0.5,0.25,1", "--metallic", "1",
                          "--roughness", (dir / "roughness.png").string(), "--occlusion", "0.2", "-o",
                          (dir / "hdrp_{texture}.png").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const RawImage mask_map = read_raw(dir / "hdrp_mask_map.png");
  ASSERT_EQ(mask_map.channels, 4);
  for (int i = 0; i < 256; ++i) {
    EXPECT_EQ(mask_map.samples[i * 4 + 0], 255);      // metallic
    EXPECT_EQ(mask_map.samples[i * 4 + 1], 51);       // occlusion 0.2, linear
    EXPECT_EQ(mask_map.samples[i * 4 + 2], 255);      // detail mask default 1
    EXPECT_EQ(mask_map.samples[i * 4 + 3], 255 - i);  // smoothness = 1 − roughness, every code exact
  }
  const RawImage base = read_raw(dir / "hdrp_base_color.png");
  EXPECT_EQ(base.samples[0], 188);  // 0.5 linear in sRGB 8-bit
  EXPECT_EQ(base.samples[1], 137);  // 0.25
  EXPECT_EQ(base.samples[3], 255);  // mask default 1
  // 16-bit output: colour is written linear.
  const auto wide = matbake({"pack", "--layout", "gltf-orm", "--base-color", "0.5", "--metallic", "0",
                             "--roughness", "0.5", "--bits", "16", "-o", (dir / "w_{texture}.png").string()});
  ASSERT_EQ(wide.exit_code, 0) << wide.err;
  EXPECT_EQ(read_raw(dir / "w_base_color.png").samples[0], 32768);
  EXPECT_EQ(read_raw(dir / "w_orm.png").samples, std::vector<double>({65535, 32768, 0}));
}

TEST(CliPack, BadInputsAndUsage) {
  TempDir dir;
  write_raw(dir / "big.png", 4, 4, 1, "uint8", std::vector<double>(16, 10));
  write_raw(dir / "small.png", 2, 2, 3, "uint8", std::vector<double>(12, 10));
  write_raw(dir / "nan.exr", 3, 2, 1, "float", {0.5, 0.5, 0.5, 0.5, std::nan(""), 0.5});
  // Valid JSON of the wrong type: nlohmann's type_error ended `pack` with exit 134.
  write_bytes(dir / "typed.json", R"({"name": 3, "textures": [{"name": "t", "channels": [{"source": "kd"}]}]})");
  const std::string big = (dir / "big.png").string(), small = (dir / "small.png").string();
  const std::string out = (dir / "o_{texture}.png").string();
  const auto before = list_folder(dir.path());

  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string path, problem;
  };
  const std::vector<Case> cases = {
      {{"--kd", (dir / "none.png").string(), "--ks", "0.04", "--gloss", "0.5"}, 1, (dir / "none.png").string(), "no such file"},
      {{"--kd", "0.5", "--ks", "0.04", "--gloss", (dir / "nan.exr").string()}, 1, (dir / "nan.exr").string(),
       "contains 1 NaN and 0 Inf samples (the first at x 1, y 1, channel 0)"},
      {{"--kd", small, "--ks", "0.04", "--gloss", big}, 1, small, "2x2, but " + big + " is 4x4"},
      {{"--kd", "1.5", "--ks", "0.04", "--gloss", "0.5"}, 2, "", "--kd: '1.5': values are in [0, 1]"},
      {{"--kd", "0.5", "--ks", "0.04"}, 2, "", "layout schuler needs gloss"},
      {{"--kd", "0.5,0.5", "--ks", "0.04", "--gloss", "0.5"}, 2, "", "--kd: '0.5,0.5': 1 or 3 numbers expected, got 2"},
      {{"--layout", "nope", "--kd", "0.5"}, 2, "", "layout 'nope': no preset of that name (presets: gltf-metal-rough, "},
      {{"--layout", (dir / "typed.json").string(), "--kd", "0.5"}, 1, (dir / "typed.json").string(),
       "[json.exception.type_error.302] type must be string, but is number"},
  };
  for (const Case& c : cases) {
    const auto r = matbake(concat(concat({"pack"}, c.args), {"-o", out}));
    EXPECT_EQ(r.exit_code, c.exit_code) << c.problem << "\n" << r.err;
    expect_one_error_line(r, c.path, c.problem);
  }
  EXPECT_EQ(list_folder(dir.path()), before);  // nothing written, no temporary left
  // Two outputs wanted, one given; an output that is an input.
  const auto count = matbake({"pack", "--kd", "0.5", "--ks", "0.04", "--gloss", "0.5", "-o", (dir / "x.png").string()});
  EXPECT_EQ(count.exit_code, 2);
  expect_one_error_line(count, "", "layout schuler writes 2 textures (a, b): give as many outputs, or one path with {texture}");
  const std::string bytes = read_bytes(dir / "big.png");
  const auto clobber = matbake({"pack", "--kd", "0.5", "--ks", "0.04", "--gloss", big, "-o", big, "-o",
                                (dir / "b.png").string()});
  EXPECT_EQ(clobber.exit_code, 2);
  expect_one_error_line(clobber, big, "is an input; matbake never overwrites its inputs");
  EXPECT_EQ(read_bytes(dir / "big.png"), bytes);
  // Two outputs that are one file.
  const auto twice = matbake({"pack", "--kd", "0.5", "--ks", "0.04", "--gloss", "0.5", "-o", (dir / "s.png").string(), "-o",
                              (dir / "s.png").string()});
  EXPECT_EQ(twice.exit_code, 2);
  expect_one_error_line(twice, (dir / "s.png").string(), "is written twice (texture a and texture b)");
  EXPECT_FALSE(fs::exists(dir / "s.png"));
}

TEST(CliWorkflow, ReportsBothConversionsAndConvertsBack) {
  TempDir dir;
  // Schüler pair: a gold texel (Kd 0, Ks gold) and a plastic one (Kd red, Ks 0.04).
  const auto packed = matbake({"pack", "--kd", "0", "--ks", "1,0.78,0.34", "--gloss", "0.75", "-o",
                               (dir / "gold_{texture}.png").string()});
  ASSERT_EQ(packed.exit_code, 0) << packed.err;
  const auto r = matbake({"--json", "workflow", "--from", "schuler", (dir / "gold_a.png").string(),
                          (dir / "gold_b.png").string(), "--to", "gltf-orm", "-o", (dir / "mr_{texture}.png").string(),
                          "--report", (dir / "report.json").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc, nlohmann::json::parse(read_bytes(dir / "report.json")));
  EXPECT_EQ(doc["direction"], "spec-gloss to metal-rough");
  EXPECT_LT(doc["errors"]["specular_f0_abs"]["max"].get<double>(), 1e-6);
  EXPECT_GT(doc["khronos_converter_errors"]["lobe_relative_rms"]["mean"].get<double>(),
            doc["errors"]["lobe_relative_rms"]["mean"].get<double>());
  const RawImage orm = read_raw(dir / "mr_orm.png");
  EXPECT_EQ(orm.samples[0], 255);  // occlusion default
  EXPECT_EQ(orm.samples[2], 255);  // metallic 1
  // And back to Schüler's pair: gold's Ks codes again.
  const auto back = matbake({"workflow", "--from", "gltf-orm", (dir / "mr_base_color.png").string(),
                             (dir / "mr_orm.png").string(), "--to", "schuler", "-o", (dir / "sg_{texture}.png").string()});
  ASSERT_EQ(back.exit_code, 0) << back.err;
  const RawImage b = read_raw(dir / "sg_b.png"), b0 = read_raw(dir / "gold_b.png");
  for (int c = 0; c < 3; ++c) EXPECT_EQ(b.samples[c], b0.samples[c]) << c;
  EXPECT_NEAR(b.samples[3], b0.samples[3], 1);  // gloss through the 8-bit roughness
  // Nothing to convert.
  const auto none = matbake({"workflow", "--kd", "0.5", "--ks", "0.04", "--gloss", "0.5", "--to", "schuler", "-o",
                             (dir / "n_{texture}.png").string()});
  EXPECT_EQ(none.exit_code, 2);
}

// A spec-gloss material written in gltf-pbr keeps its normal and emissive maps, through the
// workflow command and a manifest material alike; without an emissive map no emissive texture.
TEST(CliWorkflow, SpecGlossMaterialKeepsItsNormalAndEmissiveMaps) {
  TempDir dir;
  std::vector<double> normal, emissive, kd;
  for (int i = 0; i < 16; ++i) {
    const double angle = 0.3 * i, x = 0.5 * std::sin(angle), y = 0.5 * std::cos(angle), z = std::sqrt(1 - x * x - y * y);
    normal.insert(normal.end(), {std::round((0.5 * x + 0.5) * 255), std::round((0.5 * y + 0.5) * 255),
                                 std::round((0.5 * z + 0.5) * 255)});
    emissive.insert(emissive.end(), {double(i * 16), double(255 - i * 16), 77});
    kd.insert(kd.end(), {double(40 + i), 90, 120});
  }
  write_raw(dir / "n.png", 4, 4, 3, "uint8", normal);
  write_raw(dir / "e.png", 4, 4, 3, "uint8", emissive);
  write_raw(dir / "d.png", 4, 4, 3, "uint8", kd);
  const auto expect_maps = [&](const fs::path& normal_file, const fs::path& emissive_file) {
    const RawImage n = read_raw(normal_file), e = read_raw(emissive_file);
    ASSERT_EQ(n.samples.size(), normal.size());
    for (std::size_t i = 0; i < normal.size(); ++i) EXPECT_NEAR(n.samples[i], normal[i], 1) << i;
    EXPECT_EQ(e.samples, emissive);
  };
  const RunResult run = matbake({"workflow", "--kd", (dir / "d.png").string(), "--ks", "0.04", "--gloss", "0.6",
                                 "--normal", (dir / "n.png").string(), "--emissive", (dir / "e.png").string(),
                                 "--layout", "gltf-pbr", "-o", (dir / "wf_{texture}.png").string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  expect_maps(dir / "wf_normal.png", dir / "wf_emissive.png");

  write_bytes(dir / "lib.toml", "output = \"out\"\n"
                                "[materials.sg]\nsources = { kd = \"d.png\", ks = 0.04, gloss = 0.6, normal = \"n.png\", "
                                "emissive = \"e.png\" }\nlayout = \"gltf-pbr\"\n"
                                "[materials.plain]\nsources = { kd = \"d.png\", ks = 0.04, gloss = 0.6 }\nlayout = \"gltf-pbr\"\n");
  const RunResult built = matbake({"build", (dir / "lib.toml").string()});
  ASSERT_EQ(built.exit_code, 0) << built.err;
  expect_maps(dir / "out/materials/sg_normal.png", dir / "out/materials/sg_emissive.png");
  EXPECT_FALSE(fs::exists(dir / "out/materials/plain_emissive.png"));
  EXPECT_FALSE(fs::exists(dir / "out/materials/plain_normal.png"));
  EXPECT_TRUE(fs::exists(dir / "out/materials/plain_orm.png"));
  // Up to date afterwards: the plan expects the textures the run wrote, no more.
  const RunResult again = matbake({"build", (dir / "lib.toml").string(), "-n"});
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.out.find("material:"), std::string::npos) << again.out;
}

// Half samples into PNG (8 or 16-bit only) are refused through every door before anything is
// written: pack's --bits (naming the flag), unpack's --bits with --format, a manifest material's
// bits with its format (at the key's line and column).
TEST(CliPack, SampleTypesTheFormatCannotStoreAreRefusedAtEveryDoor) {
  TempDir dir;
  const auto before = list_folder(dir.path());
  const RunResult pack = matbake({"pack", "--bits", "half", "--layout", "gltf-orm", "--base-color", "1,0.766,0.336",
                                  "--metallic", "1", "--roughness", "0.3", "-o", (dir / "x_{texture}.png").string()});
  EXPECT_EQ(pack.exit_code, 2);
  expect_one_error_line(pack, "--bits", "PNG stores 8 or 16-bit samples, not half");
  const RunResult unpack = matbake({"unpack", "--bits", "float", "--format", "png", "-o", (dir / "maps").string(),
                                    (dir / "a.png").string(), (dir / "b.png").string()});
  EXPECT_EQ(unpack.exit_code, 2);
  expect_one_error_line(unpack, "--bits", "PNG stores 8 or 16-bit samples, not float");
  EXPECT_EQ(list_folder(dir.path()), before);

  write_bytes(dir / "lib.toml", "output = \"out\"\n[materials.gold]\nsources = { base_color = \"1,0.766,0.336\", "
                                "metallic = 1, roughness = 0.3 }\nlayout = \"gltf-orm\"\nbits = \"half\"\n");
  const RunResult built = matbake({"build", (dir / "lib.toml").string()});
  EXPECT_EQ(built.exit_code, 1);  // as every manifest error
  expect_one_error_line(built, (dir / "lib.toml").string() + ":5:8",
                        "materials.gold: bits = \"half\" with format = \"png\": PNG stores 8 or 16-bit samples, not half");
  EXPECT_FALSE(fs::exists(dir / "out"));
  // With EXR the same material is written, as half.
  write_bytes(dir / "lib.toml", read_bytes(dir / "lib.toml") + "format = \"exr\"\n");
  const RunResult exr = matbake({"build", (dir / "lib.toml").string()});
  ASSERT_EQ(exr.exit_code, 0) << exr.err;
  EXPECT_EQ(read_raw(dir / "out/materials/gold_base_color.exr").format, "half");
}

// HDR emission (an EXR of 3.0) into an 8-bit gltf-pbr emissive texture is refused, naming the
// file and the source, before any texture is written (it was clipped to 1 without a word); into
// EXR it is written as it is.
TEST(CliPack, ValuesAnIntegerFileCannotHoldAreRefusedNotClipped) {
  TempDir dir;
  write_raw(dir / "e.exr", 2, 1, 3, "float", {3, 0.5, 0.25, 0, 0, 0});
  const std::vector<std::string> sources = {"--base-color", "0.5", "--metallic", "0", "--roughness", "0.5",
                                            "--emissive", (dir / "e.exr").string()};
  const auto before = list_folder(dir.path());
  const RunResult clipped = matbake(concat({"pack", "--layout", "gltf-pbr", "-o", (dir / "x_{texture}.png").string()}, sources));
  EXPECT_EQ(clipped.exit_code, 1);
  expect_one_error_line(clipped, (dir / "x_emissive.png").string(),
                        "texture emissive holds 3.000000 (from emissive), outside the [0, 1] an 8-bit file stores");
  EXPECT_EQ(list_folder(dir.path()), before);
  const RunResult exr = matbake(concat({"pack", "--layout", "gltf-pbr", "-o", (dir / "x_{texture}.exr").string()}, sources));
  ASSERT_EQ(exr.exit_code, 0) << exr.err;
  EXPECT_EQ(read_raw(dir / "x_emissive.exr").samples[0], 3.0);
}

// A layout channel with no default needs its map: refused (usage, exit 2, nothing written) though
// the texture holding it would have no map at all, while a texture whose channels all have
// defaults and no map is simply not written.
TEST(CliPack, ARequiredMapIsRefusedEvenWhereItsTextureWouldBeSkipped) {
  TempDir dir;
  const auto r = matbake({"pack", "--layout", "gltf-orm", "--roughness", "0.5", "--metallic", "0", "-o",
                          (dir / "x_{texture}.png").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "matbake: error: layout gltf-orm needs base_color\n");
  EXPECT_TRUE(list_folder(dir.path()).empty());
  ASSERT_EQ(matbake({"pack", "--layout", "gltf-pbr", "--base-color", "0.5", "--roughness", "0.5", "--metallic", "0", "-o",
                     (dir / "y_{texture}.png").string()}).exit_code, 0);
  EXPECT_FALSE(fs::exists(dir / "y_normal.png"));
  EXPECT_FALSE(fs::exists(dir / "y_emissive.png"));
}

}  // namespace
}  // namespace matbake::test
