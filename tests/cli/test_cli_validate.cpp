// `matbake validate` and `matbake materials` end to end: exit codes 0 / 3 / 1 / 2, the JSON report,
// the heatmap file, and bad inputs.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

TEST(CliMaterials, ListsTheTableWithBothEncodings) {
  const auto r = matbake({"--json", "materials"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  ASSERT_EQ(doc["materials"].size(), 32u);
  const auto& water = doc["materials"][0];
  EXPECT_EQ(water["name"], "water");
  EXPECT_EQ(water["code_gamma22"], nlohmann::json::array({43}));  // 0.02 encodes to 43, the table prints 44
  EXPECT_EQ(water["code_srgb"], nlohmann::json::array({39}));
  EXPECT_EQ(water["table_code"], nlohmann::json::array({44}));
  const auto text = matbake({"materials"});
  EXPECT_NE(text.out.find("gold             metal"), std::string::npos) << text.out;
}

TEST(CliValidate, ExitCodesReportAndHeatmap) {
  TempDir dir;
  // Pair B, 8-bit sRGB: 3 dielectric texels (F0 0.04: code 57), one in the semiconductor gap (code 150).
  write_raw(dir / "b.png", 4, 1, 4, "uint8", {57, 57, 57, 128, 57, 57, 57, 128, 57, 57, 57, 128, 150, 150, 150, 128});
  const std::string b = (dir / "b.png").string();
  const auto strict = matbake({"--json", "validate", "--gate", "--ks", b, "--heatmap", (dir / "map.png").string()});
  EXPECT_EQ(strict.exit_code, 3) << strict.err;
  const auto doc = nlohmann::json::parse(strict.out);
  EXPECT_EQ(doc["classes"]["dielectric"], 3);
  EXPECT_EQ(doc["classes"]["semiconductor"], 1);
  EXPECT_EQ(doc["flags"]["semiconductor_gap"], 1);
  EXPECT_EQ(doc["violation_fraction"], 0.25);
  EXPECT_EQ(doc["worst"][0]["x"], 3);
  EXPECT_EQ(doc["passed"], false);
  const RawImage map = read_raw(dir / "map.png");
  EXPECT_EQ(map.samples, std::vector<double>({40, 170, 70, 40, 170, 70, 40, 170, 70, 255, 150, 0}));
  // Allowed share: passes. Over it without --gate (the default): advisory (exit 0, said, not passed).
  EXPECT_EQ(matbake({"validate", "--gate", "--ks", b, "--max-violations", "0.25"}).exit_code, 0);
  const auto advisory = matbake({"--json", "validate", "--ks", b});
  EXPECT_EQ(advisory.exit_code, 0) << advisory.err;
  EXPECT_EQ(nlohmann::json::parse(advisory.out)["passed"], false);
  EXPECT_EQ(nlohmann::json::parse(advisory.out)["gate"], false);
  EXPECT_NE(matbake({"validate", "--ks", b}).out.find("over the limit (advisory: gate off)"), std::string::npos);
  // The curve moves the class: code 57 under gamma 2.2 is 0.0443 (still dielectric), 150 is 0.311.
  const auto g22 = matbake({"--json", "validate", "--ks", b, "--transfer", "gamma2.2"});
  EXPECT_NEAR(nlohmann::json::parse(g22.out)["f0_stats"][0]["min"].get<double>(), std::pow(57 / 255.0, 2.2), 1e-6);
}

TEST(CliValidate, WholePairMetalRoughAndMaterial) {
  TempDir dir;
  // Gold with a diffuse colour: flagged as metal_with_diffuse, and measured against the table's gold.
  ASSERT_EQ(matbake({"pack", "--kd", "0.3", "--mask", "1", "--ks", "0.966,0.82,0.389", "--gloss", "0.5", "--size",
                     "2x2", "-o", (dir / "g_{texture}.png").string()})
                .exit_code,
            0);
  const auto r = matbake({"--json", "validate", "--from", "schuler", (dir / "g_a.png").string(),
                          (dir / "g_b.png").string(), "--material", "gold", "--gate"});
  EXPECT_EQ(r.exit_code, 3);
  const auto doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc["flags"]["metal_with_diffuse"], 4);
  EXPECT_EQ(doc["material"]["share_within"], 1.0);
  // Metal-rough maps: a pure metal (base gold, metallic 1) is clean.
  ASSERT_EQ(matbake({"pack", "--layout", "gltf-metal-rough", "--base-color", "0.966,0.82,0.389", "--metallic", "1",
                     "--roughness", "0.3", "-o", (dir / "mr_{texture}.png").string()})
                .exit_code,
            0);
  EXPECT_EQ(matbake({"validate", "--from", "gltf-metal-rough", (dir / "mr_base_color.png").string(),
                     (dir / "mr_metallic_roughness.png").string(), "--material", "gold"})
                .exit_code,
            0);
}

// A metal-rough material is told what is wrong in base colour and metallic terms, a spec-gloss one in
// F0 and diffuse terms: the same texels, the same flags, each in its own workflow's words (the
// summary, --json and a build's warning).
TEST(CliValidate, FlagsSpeakTheInputsWorkflow) {
  TempDir dir;
  // A dark metal (base 0.3, metallic 1: F0 0.3) and a non-metal darker than charcoal (base 0.01).
  ASSERT_EQ(matbake({"pack", "--layout", "gltf-metal-rough", "--base-color", "0.3", "--metallic", "1", "--roughness", "0.5",
                     "--size", "2x1", "-o", (dir / "metal_{texture}.png").string()}).exit_code, 0);
  ASSERT_EQ(matbake({"pack", "--layout", "gltf-metal-rough", "--base-color", "0.01", "--metallic", "0", "--roughness", "0.5",
                     "--size", "2x1", "-o", (dir / "coal_{texture}.png").string()}).exit_code, 0);
  const auto metal = matbake({"validate", "--from", "gltf-metal-rough", (dir / "metal_base_color.png").string(),
                              (dir / "metal_metallic_roughness.png").string()});
  EXPECT_NE(metal.out.find("semiconductor_gap      2: metal base colour darker than any real metal"), std::string::npos)
      << metal.out;
  const auto coal = matbake({"--json", "validate", "--from", "gltf-metal-rough", (dir / "coal_base_color.png").string(),
                             (dir / "coal_metallic_roughness.png").string()});
  const auto doc = nlohmann::json::parse(coal.out);
  EXPECT_EQ(doc["vocabulary"], "metal-rough");
  EXPECT_EQ(doc["flags"]["albedo_out_of_range"], 2);
  EXPECT_EQ(doc["flag_meanings"]["albedo_out_of_range"],
            "non-metal base colour darker than charcoal (0.02) or brighter than toothpaste (0.94)");
  // The same F0 given as spec-gloss speaks of F0.
  const auto ks = matbake({"validate", "--ks", "0.3"});
  EXPECT_NE(ks.out.find("semiconductor_gap      1: F0 in the semiconductor gap"), std::string::npos) << ks.out << ks.err;
  // A build's warning names the most common flag in the material's terms.
  write_bytes(dir / "m.toml", "[materials.coal]\nsources = { base_color = \"coal_base_color.png\", metallic = 0.0, roughness = 0.5 }\n");
  const auto built = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(built.exit_code, 0) << built.err;
  EXPECT_NE(built.err.find("most: non-metal base colour darker than charcoal (0.02) or brighter than toothpaste (0.94) (2 texels)"),
            std::string::npos) << built.err;
}

TEST(CliValidate, BadInputs) {
  TempDir dir;
  write_raw(dir / "a.png", 2, 2, 4, "uint8", std::vector<double>(16, 100));
  write_raw(dir / "b.png", 3, 2, 4, "uint8", std::vector<double>(24, 100));
  write_raw(dir / "nan.exr", 2, 1, 3, "float", {0.04, 0.04, 0.04, 0.04, std::nan(""), 0.04});
  const std::string a = (dir / "a.png").string(), b = (dir / "b.png").string(), nan = (dir / "nan.exr").string();
  const auto sizes = matbake({"validate", "--from", "schuler", a, b});
  EXPECT_EQ(sizes.exit_code, 1);
  expect_one_error_line(sizes, b, "3x2, but " + a + " is 2x2");
  const auto bad = matbake({"validate", "--ks", nan});
  EXPECT_EQ(bad.exit_code, 1);
  expect_one_error_line(bad, nan, "contains 1 NaN and 0 Inf samples (the first at x 1, y 0, channel 1)");
  const auto unknown = matbake({"validate", "--ks", a, "--material", "sliver"});
  EXPECT_EQ(unknown.exit_code, 2);
  expect_one_error_line(unknown, "", "unknown material 'sliver'; near: silver");
  const auto nothing = matbake({"validate", "--kd", a});
  EXPECT_EQ(nothing.exit_code, 2);
  const auto missing = matbake({"validate", "--ks", (dir / "none.png").string()});
  EXPECT_EQ(missing.exit_code, 1);
  expect_one_error_line(missing, (dir / "none.png").string(), "no such file");
}

}  // namespace
}  // namespace matbake::test
