// Two front ends, one decision: each operation a manifest can express (pack, workflow, validate,
// export with AO) run once as a command and once from a manifest with the same settings — the
// defaults, then each non-default option once — must give the same bytes. One manifest holds every
// case (one `matbake build`), and each case's command runs beside it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <map>
#include <sstream>
#include <random>

#include "lib/src/gltf/document.hpp"
#include "matbake/ao_params.hpp"
#include "matbake/bake_ao_params.hpp"
#include "matbake/export_params.hpp"
#include "matbake/image.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/param_values.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;


// Noise images, so that every code path (sRGB curve, rounding) shows in the bytes.
void write_noise(const fs::path& path, int size, int channels, unsigned seed, int lo = 0, int hi = 255) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> code(lo, hi);
  std::vector<double> samples(std::size_t(size) * std::size_t(size) * std::size_t(channels));
  for (double& s : samples) s = code(rng);
  write_raw(path, size, size, channels, "uint8", samples);
}

// A command's outputs against the build's, file by file.
void expect_same_files(const std::vector<fs::path>& from_command, const std::vector<fs::path>& from_build,
                       const std::string& what) {
  ASSERT_EQ(from_command.size(), from_build.size()) << what;
  for (std::size_t i = 0; i < from_command.size(); ++i) {
    ASSERT_TRUE(fs::exists(from_command[i])) << what << ": " << from_command[i];
    ASSERT_TRUE(fs::exists(from_build[i])) << what << ": " << from_build[i];
    EXPECT_TRUE(read_bytes(from_command[i]) == read_bytes(from_build[i]))
        << what << ": " << from_command[i] << " differs from " << from_build[i];
  }
}

struct MaterialCase {
  std::string name;
  std::string manifest;                  // the material's keys
  std::vector<std::string> command;      // the command (without -o)
  std::vector<std::string> textures;     // the layout's texture names
  std::string extension = "png";
};

// The _AO values of a written scene, node by node, primitive by primitive.
std::vector<float> ao_values(const fs::path& file) {
  auto doc = gltf::read_document(file);
  EXPECT_TRUE(doc) << doc.error().to_string();
  std::vector<float> values;
  if (!doc) return values;
  for (const auto& node : doc->json["nodes"]) {
    if (!node.contains("mesh")) continue;
    for (const auto& primitive : doc->json["meshes"][node["mesh"].get<std::size_t>()]["primitives"]) {
      if (!primitive["attributes"].contains("_AO")) continue;
      const std::vector<float> v = float_accessor(*doc, primitive["attributes"]["_AO"].get<int>());
      values.insert(values.end(), v.begin(), v.end());
    }
  }
  return values;
}

class Parity : public ::testing::Test {
 protected:
  void SetUp() override {
    write_noise(dir / "kd.png", 8, 3, 1);
    write_noise(dir / "gloss.png", 8, 1, 2);
    write_noise(dir / "gloss16.png", 16, 1, 3);
    write_noise(dir / "ks.png", 8, 3, 4, 10, 60);  // dielectric-ish F0
    write_noise(dir / "base.png", 8, 3, 5);
    write_noise(dir / "rough.png", 8, 1, 6);
    write_noise(dir / "metal.png", 8, 1, 7);
    write_noise(dir / "pair_a.png", 8, 4, 8);          // Schüler's A: Kd + mask
    write_noise(dir / "pair_b.png", 8, 4, 9, 10, 60);  // B: F0 + gloss
    fs::create_directories(dir / "cli");
  }

  // Runs a command; its outputs go to cli/.
  void run_command(std::vector<std::string> args, int expected_exit = 0) {
    for (std::string& a : args) {
      const std::string file = a.substr(0, a.find(".png:") == std::string::npos ? a.size() : a.find(".png:") + 4);
      if (file.ends_with(".png") && !a.starts_with("cli/") && fs::exists(dir / file)) a = (dir / a).string();
      if (a.starts_with("cli/")) a = (dir / a).string();
    }
    const RunResult r = matbake(args);
    EXPECT_EQ(r.exit_code, expected_exit) << args[0] << ": " << r.err;
  }

  json build(const std::string& manifest) {
    write_bytes(dir / "assets.toml", manifest);
    const RunResult r = matbake({"--json", "build", (dir / "assets.toml").string()});
    EXPECT_NE(r.out, "") << r.err;
    return r.out.empty() ? json() : json::parse(r.out);
  }

  TempDir dir;
};

// Each flag of a command's tree as --help lists it: under its branch's heading, with the flags it
// applies with spelt as flags.
template <class Root>
void expect_help_headings(const std::string& command, const params::Tree<Root>& tree,
                          const std::vector<std::string>& headings) {
  const RunResult help = matbake({command, "--help"});
  ASSERT_EQ(help.exit_code, 0);
  std::map<std::string, std::string> heading_of;  // flag → the heading above it
  std::map<std::string, std::string> line_of;
  std::string heading, last;
  std::istringstream lines(help.out);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line[0] != ' ' && line.back() == ':') heading = line.substr(0, line.size() - 1);
    if (line.rfind("  --", 0) != 0) {  // a long help's further lines
      if (!last.empty() && line.rfind("   ", 0) == 0) line_of[last] += line;
      continue;
    }
    last = line.substr(2, line.find_first_of(" =", 2) - 2);
    heading_of[last] = heading;
    line_of[last] = line;
  }
  for (std::size_t b = 0; b < tree.size(); ++b) {
    for (const params::Spec* spec : tree[b].specs) {
      if (spec->manifest_only) continue;
      std::string flag = params::flag_name(*spec, tree[b].flag_prefix);
      if (spec->kind == params::Kind::flag && line_of.count(flag) == 0) flag = "--no-" + flag.substr(2);
      SCOPED_TRACE(flag);
      EXPECT_EQ(heading_of[flag], headings.at(b));
      for (const params::Condition& c : spec->needs) {
        EXPECT_NE(line_of[flag].find("(with " + params::flag_name(params::Spec{.name = c.name}, tree[b].flag_prefix)),
                  std::string::npos) << line_of[flag];
      }
    }
  }
}

TEST(Help, EveryTreeFlagStandsUnderItsBranchsHeading) {
  expect_help_headings("export", exporter::request_tree(),
                       {"Options", "Options", "Texture delivery (docs/delivery.md)", "Ambient occlusion"});
  expect_help_headings("bake-ao", bake_ao::request_tree(), {"Options", "Texture delivery (docs/delivery.md)", "Options"});
}

TEST_F(Parity, PackAndWorkflowGiveTheManifestsBytes) {
  const std::vector<MaterialCase> cases = {
      {"defaults", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss.png\" }\nlayout = \"schuler\"",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss.png"}, {"a", "b"}},
      {"gamma", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss.png\" }\nlayout = \"schuler\"\ntransfer = \"gamma2.2\"",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss.png", "--transfer", "gamma2.2"}, {"a", "b"}},
      {"bits16", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss.png\" }\nlayout = \"schuler\"\nbits = \"16\"",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss.png", "--bits", "16"}, {"a", "b"}},
      {"exr", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss.png\" }\nlayout = \"schuler\"\nformat = \"exr\"",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss.png"}, {"a", "b"}, "exr"},
      {"resized", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss16.png\" }\nlayout = \"schuler\"\nresize = true",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss16.png", "--resize"}, {"a", "b"}},
      {"decoded", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss.png\" }\nlayout = \"schuler\"\ndecode = \"linear\"",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss.png", "--decode", "linear"}, {"a", "b"}},
      {"orm", "sources = { base_color = \"base.png\", metallic = \"metal.png\", roughness = \"rough.png\" }\nlayout = \"gltf-orm\"",
       {"pack", "--layout", "gltf-orm", "--base-color", "base.png", "--metallic", "metal.png", "--roughness", "rough.png"},
       {"base_color", "orm"}},
      {"packed", "packed = { layout = \"schuler\", files = [\"pair_a.png\", \"pair_b.png\"] }\nlayout = \"unreal-orm\"",
       {"workflow", "--to", "unreal-orm", "--from", "schuler", "pair_a.png", "pair_b.png"}, {"base_color", "orm"}},
      {"packed_override",
       "packed = { layout = \"schuler\", files = [\"pair_a.png\", \"pair_b.png\"] }\nsources = { gloss = 0.3 }\n"
       "layout = \"unreal-orm\"",
       {"workflow", "--layout", "unreal-orm", "--from", "schuler", "pair_a.png", "pair_b.png", "--gloss", "0.3"},
       {"base_color", "orm"}},
      {"constants", "sources = { kd = [0.5, 0.4, 0.3], ks = 0.04, gloss = 0.6 }\nlayout = \"schuler\"\nsize = \"8x4\"",
       {"pack", "--kd", "0.5,0.4,0.3", "--ks", "0.04", "--gloss", "0.6", "--size", "8x4"}, {"a", "b"}},
      {"to_metal_rough", "sources = { kd = \"kd.png\", ks = \"ks.png\", gloss = \"gloss.png\" }\nlayout = \"gltf-orm\"",
       {"workflow", "--to", "gltf-orm", "--kd", "kd.png", "--ks", "ks.png", "--gloss", "gloss.png"}, {"base_color", "orm"}},
      {"walter", "sources = { kd = \"kd.png\", ks = \"ks.png\", gloss = \"gloss.png\" }\nlayout = \"gltf-orm\"\nmapping = \"walter\"",
       {"workflow", "--to", "gltf-orm", "--kd", "kd.png", "--ks", "ks.png", "--gloss", "gloss.png", "--mapping", "walter"},
       {"base_color", "orm"}},
      {"stored", "sources = { kd = \"kd.png\", ks = 0.04, gloss = \"gloss.png\" }\nlayout = \"schuler\"\npng_compression = 0",
       {"pack", "--kd", "kd.png", "--ks", "0.04", "--gloss", "gloss.png", "--png-compression", "0"}, {"a", "b"}},
      {"small", "sources = { kd = \"kd.png\", ks = \"ks.png\", gloss = \"gloss.png\" }\nlayout = \"gltf-orm\"\npng_compression = \"small\"",
       {"workflow", "--to", "gltf-orm", "--kd", "kd.png", "--ks", "ks.png", "--gloss", "gloss.png", "--png-compression", "small"},
       {"base_color", "orm"}},
      {"channels",
       "sources = { kd = { file = \"pair_a.png\", channel = \"rgb\" }, mask = { file = \"pair_a.png\", channel = \"a\" }, "
       "ks = { file = \"pair_b.png\", channel = \"rgb\" }, gloss = { file = \"pair_b.png\", channel = \"a\" } }\nlayout = \"schuler\"",
       {"pack", "--kd", "pair_a.png:rgb", "--mask", "pair_a.png:a", "--ks", "pair_b.png:rgb", "--gloss", "pair_b.png:a"},
       {"a", "b"}},
      {"roughness_from_g",
       "sources = { base_color = \"base.png\", metallic = 0.0, roughness = { file = \"base.png\", channel = \"g\" } }\n"
       "layout = \"gltf-orm\"",
       {"pack", "--layout", "gltf-orm", "--base-color", "base.png", "--metallic", "0", "--roughness", "base.png:g"},
       {"base_color", "orm"}},
      {"rgb_diffuse_pair", "packed = { layout = \"schuler\", files = [\"kd.png\", \"pair_b.png\"] }\nlayout = \"unreal-orm\"",
       {"workflow", "--layout", "unreal-orm", "--from", "schuler", "kd.png", "pair_b.png"}, {"base_color", "orm"}},
      {"to_spec_gloss", "sources = { base_color = \"base.png\", metallic = \"metal.png\", roughness = \"rough.png\" }\nlayout = \"schuler\"",
       {"workflow", "--to", "schuler", "--base-color", "base.png", "--metallic", "metal.png", "--roughness", "rough.png"},
       {"a", "b"}},
  };
  std::string manifest = "[validate]\nenabled = false\n";
  for (const MaterialCase& c : cases) manifest += "\n[materials." + c.name + "]\n" + c.manifest + "\n";
  const json report = build(manifest);
  ASSERT_EQ(report.value("failed", -1), 0) << report.dump(2);
  for (const MaterialCase& c : cases) {
    std::vector<std::string> args = c.command;
    args.push_back("-o");
    args.push_back("cli/" + c.name + "_{texture}." + c.extension);
    run_command(args);
    std::vector<fs::path> from_command, from_build;
    for (const std::string& t : c.textures) {
      from_command.push_back(dir / "cli" / (c.name + "_" + t + "." + c.extension));
      from_build.push_back(dir / "out" / "materials" / (c.name + "_" + t + "." + c.extension));
    }
    expect_same_files(from_command, from_build, c.name);
  }
  // The level reaches the file: the zlib header's FLEVEL (its second byte) says fastest, default or
  // maximum compression (noise this small deflates to the same size at every level).
  auto zlib_level_byte = [&](const std::string& file) {
    const std::string bytes = read_bytes(dir / "out" / "materials" / file);
    const std::size_t idat = bytes.find("IDAT");
    return idat == std::string::npos ? -1 : int(std::uint8_t(bytes[idat + 5]));
  };
  EXPECT_EQ(zlib_level_byte("stored_a.png"), 0x01);
  EXPECT_EQ(zlib_level_byte("defaults_a.png"), 0x9c);
  EXPECT_EQ(zlib_level_byte("small_orm.png"), 0xda);
}

TEST_F(Parity, ValidateWritesTheManifestsReportAndHeatmap) {
  struct Case {
    std::string name, manifest;
    std::vector<std::string> command;
  };
  const std::vector<Case> cases = {
      {"defaults", "validate = { heatmap = true }", {}},
      {"options", "reference = \"gold\"\nvalidate = { tolerance = 0.2, max_violations = 0.5, heatmap = true, worst = 3 }",
       {"--material", "gold", "--tolerance", "0.2", "--max-violations", "0.5", "--worst", "3"}},
  };
  std::string manifest;
  for (const Case& c : cases) {
    manifest += "\n[materials." + c.name + "]\nsources = { kd = \"kd.png\", ks = \"ks.png\", gloss = 0.5 }\n" + c.manifest + "\n";
  }
  build(manifest);  // jobs whose texels are flagged fail, and write their reports all the same
  for (const Case& c : cases) {
    std::vector<std::string> args = {"validate", "--kd", "kd.png", "--ks", "ks.png", "--gloss", "0.5",
                                     "--report", "cli/" + c.name + ".validation.json",
                                     "--heatmap", "cli/" + c.name + "_validation.png"};
    args.insert(args.end(), c.command.begin(), c.command.end());
    for (std::string& a : args) {
      if (a == "kd.png" || a == "ks.png") a = (dir / a).string();
      if (a.starts_with("cli/")) a = (dir / a).string();
    }
    const RunResult r = matbake(args);
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.err;
    expect_same_files({dir / "cli" / (c.name + ".validation.json"), dir / "cli" / (c.name + "_validation.png")},
                      {dir / "out" / "materials" / (c.name + ".validation.json"),
                       dir / "out" / "materials" / (c.name + "_validation.png")},
                      c.name);
  }
}

// A material job's ball is `matbake preview` of the same sources, byte for byte: Schüler maps and
// metal-rough ones (converted per texel by the same code).
TEST_F(Parity, PreviewGivesTheManifestsBall) {
  build("\n[materials.schuler]\nsources = { kd = \"kd.png\", ks = \"ks.png\", gloss = 0.5 }\nlayout = \"schuler\"\n"
        "\n[materials.metal_rough]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\nlayout = \"gltf-orm\"\n");
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"schuler", {"--kd", (dir / "kd.png").string(), "--ks", (dir / "ks.png").string(), "--gloss", "0.5"}},
      {"metal_rough", {"--base-color", (dir / "kd.png").string(), "--metallic", "0", "--roughness", "0.5"}}};
  for (const auto& [name, sources] : cases) {
    std::vector<std::string> args = {"preview", "-o", (dir / "cli" / (name + "_preview.png")).string()};
    args.insert(args.end(), sources.begin(), sources.end());
    const RunResult r = matbake(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    expect_same_files({dir / "cli" / (name + "_preview.png")}, {dir / "out" / "materials" / (name + "_preview.png")}, name);
  }
}

TEST_F(Parity, ExportAndAoGiveTheManifestsScene) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  // One Schüler pair for painted_metal, packed from the test's noise; the other materials as in the file.
  struct Case {
    std::string name, manifest;
    std::vector<std::string> command;
    std::string mapping;  // of the material (the command's --mapping)
  };
  std::vector<Case> cases = {
      {"defaults", "", {}, ""},
      {"dielectric_ior", "dielectric_f0 = \"ior\"", {"--dielectric-f0", "ior"}, ""},
      {"no_orm", "orm = false", {"--no-orm"}, ""},
      {"walter", "", {"--mapping", "walter"}, "walter"},
      {"ao_defaults", "ao = { samples = 8 }", {"--ao-samples", "8"}, ""},
      {"ao_texture_only", "ao = { texture = 4 }", {"--ao-texture", "4"}, ""},
      {"ao_texture_options",
       "ao = { samples = 8, texture = \"16x8\", padding = 2, texel_samples = 2, bits = 16, texcoord = 0, "
       "existing_occlusion = \"replace\" }",
       {"--ao-samples", "8", "--ao-texture", "16x8", "--ao-padding", "2", "--ao-texel-samples", "2", "--ao-bits", "16",
        "--ao-texcoord", "0", "--ao-existing-occlusion", "replace"},
       ""},
  };
  // Each AO parameter once, at its description's example (with the texture it needs), both ways.
  for (const params::Param<ao::Request>& p : ao::request_params().params) {
    const bool samples = p.spec.name == "samples";  // the others at 8 samples, to stay quick
    Case c{"ao_" + p.spec.name, "ao = { " + std::string(samples ? "" : "samples = 8, ") + p.spec.name + " = " + toml_literal(p.spec),
           samples ? std::vector<std::string>{} : std::vector<std::string>{"--ao-samples", "8"}, ""};
    c.command.push_back(params::flag_name(p.spec, "ao-"));
    if (p.spec.kind != params::Kind::flag) c.command.push_back(p.spec.example);
    for (const params::Condition& need : p.spec.needs) {
      c.manifest += ", " + need.name + " = " + (need.value.empty() ? "8" : "\"" + need.value + "\"");
      c.command.insert(c.command.end(), {params::flag_name({.name = need.name}, "ao-"), need.value.empty() ? "8" : need.value});
    }
    c.manifest += " }";
    cases.push_back(std::move(c));
  }
  std::string manifest;
  for (const Case& c : cases) {
    manifest += "\n[materials.pair_" + c.name + "]\npacked = { layout = \"schuler\", files = [\"pair_a.png\", \"pair_b.png\"] }\n" +
                "validate = { enabled = false }\n" + (c.mapping.empty() ? "" : "mapping = \"" + c.mapping + "\"\n");
    manifest += "\n[scenes." + c.name + "]\ninput = \"showroom.gltf\"\noutput = \"" + c.name + "/showroom.glb\"\n" +
                "materials = { painted_metal = \"pair_" + c.name + "\" }\n" + c.manifest + "\n";
  }
  const json report = build(manifest);
  ASSERT_EQ(report.value("failed", -1), 0) << report.dump(2);
  for (const Case& c : cases) {
    fs::create_directories(dir / "cli" / c.name);
    std::vector<std::string> args = {"export", (dir / "showroom.gltf").string(), "-o",
                                     (dir / "cli" / c.name / "showroom.glb").string(), "--material",
                                     "painted_metal=" + (dir / "pair_a.png").string() + "," + (dir / "pair_b.png").string()};
    args.insert(args.end(), c.command.begin(), c.command.end());
    const RunResult r = matbake(args);
    EXPECT_EQ(r.exit_code, 0) << c.name << ": " << r.err;
    expect_same_files({dir / "cli" / c.name / "showroom.glb"}, {dir / "out" / c.name / "showroom.glb"}, c.name);
  }
}

// Normal and emissive maps through both doors: `pack --layout gltf-pbr` and a manifest material
// write the same textures (DirectX green flipped); those textures exported by `export --material
// NAME=gltf-pbr:...` and by a manifest scene give the same scene, with normalTexture and
// emissiveTexture.
TEST_F(Parity, NormalAndEmissiveMapsReachTheExportedMaterial) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> tilt(96, 160), up(230, 255);
  std::vector<double> normal;
  for (int i = 0; i < 64; ++i) normal.insert(normal.end(), {double(tilt(rng)), double(tilt(rng)), double(up(rng))});
  write_raw(dir / "nrm.png", 8, 8, 3, "uint8", normal);
  write_noise(dir / "em.png", 8, 3, 12);
  const std::string sources =
      "sources = { base_color = \"base.png\", metallic = \"metal.png\", roughness = \"rough.png\", normal = \"nrm.png\", "
      "emissive = \"em.png\" }\nnormal_y = \"directx\"\nlayout = \"gltf-pbr\"\nvalidate = { enabled = false }\n";
  run_command({"pack", "--layout", "gltf-pbr", "--base-color", "base.png", "--metallic", "metal.png", "--roughness", "rough.png",
               "--normal", "nrm.png", "--emissive", "em.png", "--normal-y", "directx", "-o", "cli/glow_{texture}.png"});
  const std::vector<std::string> textures = {"base_color", "orm", "normal", "emissive"};
  std::string files;
  for (const std::string& t : textures) files += std::string(files.empty() ? "" : ", ") + "\"cli/glow_" + t + ".png\"";
  const json report = build("[materials.glow]\n" + sources + "\n[materials.packed]\npacked = { layout = \"gltf-pbr\", files = [" +
                            files + "] }\nvalidate = { enabled = false }\n\n[scenes.scene]\ninput = \"showroom.gltf\"\n" +
                            "materials = { painted_metal = \"packed\" }\n");
  ASSERT_EQ(report.value("failed", -1), 0) << report.dump(2);
  std::vector<fs::path> from_command, from_build;
  std::string packed_files;
  for (const std::string& t : textures) {
    from_command.push_back(dir / "cli" / ("glow_" + t + ".png"));
    from_build.push_back(dir / "out/materials" / ("glow_" + t + ".png"));
    packed_files += (packed_files.empty() ? "" : ",") + (dir / "cli" / ("glow_" + t + ".png")).string();
  }
  expect_same_files(from_command, from_build, "gltf-pbr textures");
  // The first texel as float64 says: decoded, green flipped, renormalised, stored.
  const RawImage written = read_raw(dir / "cli/glow_normal.png");
  double n[3] = {2 * normal[0] / 255 - 1, -(2 * normal[1] / 255 - 1), 2 * normal[2] / 255 - 1};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(written.samples[std::size_t(c)], 255 * (0.5 * n[c] / length + 0.5), 0.5001) << c;

  run_command({"export", (dir / "showroom.gltf").string(), "-o", "cli/scene.glb", "--material", "painted_metal=gltf-pbr:" + packed_files});
  expect_same_files({dir / "cli/scene.glb"}, {dir / "out/scene.glb"}, "scene");
  auto doc = gltf::read_document(dir / "out/scene.glb");
  ASSERT_TRUE(doc) << doc.error().to_string();
  bool found = false;
  for (const auto& m : doc->json["materials"]) {
    if (m.value("name", "") != "painted_metal") continue;
    found = true;
    EXPECT_TRUE(m.contains("normalTexture")) << m.dump();
    EXPECT_TRUE(m.contains("emissiveTexture")) << m.dump();
    EXPECT_EQ(m["emissiveFactor"], json::array({1.0, 1.0, 1.0})) << m.dump();  // numbers compare by value
  }
  EXPECT_TRUE(found);
  MATBAKE_VALIDATE_OR_SKIP(validated, dir / "out/scene.glb");
  EXPECT_EQ(validated->errors, 0) << validated->summary;
  // The one warning: no TANGENT attribute, so runtimes compute MikkTSpace tangents (glTF 2.0, 3.7.2.1).
  for (const std::string& code : validated->error_and_warning_codes) {
    EXPECT_EQ(code.rfind("MESH_PRIMITIVE_GENERATED_TANGENT_SPACE ", 0), 0u) << validated->summary;
  }
}

// Issue "One request layer": bake-ao was one-sided and export/build two-sided by default (mean AO
// 0.803 against 0.596 on the showroom). All three now take ao::Options' defaults: the same values.
TEST_F(Parity, BakeAoExportAndBuildBakeTheSameValues) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  run_command({"bake-ao", (dir / "showroom.gltf").string(), "--samples", "16", "--into", "_AO", "-o",
               (dir / "cli" / "baked.glb").string()});
  run_command({"export", (dir / "showroom.gltf").string(), "--ao-samples", "16", "--ao-into", "_AO", "-o",
               (dir / "cli" / "exported.glb").string()});
  build("[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"built.glb\"\nao = { samples = 16, into = \"_AO\" }\n");
  const std::vector<float> baked = ao_values(dir / "cli" / "baked.glb");
  ASSERT_FALSE(baked.empty());
  EXPECT_EQ(ao_values(dir / "cli" / "exported.glb"), baked);
  EXPECT_EQ(ao_values(dir / "out" / "built.glb"), baked);
  double mean = 0;
  for (float v : baked) mean += v;
  mean /= double(baked.size());
  EXPECT_GT(mean, 0.7);  // one-sided: the floor's underside does not darken the objects on it
}

// A texture bake in export goes into the red channel of the material's ORM texture, at that
// texture's size, its green and blue kept: painted_metal's ORM (8×8, from the pair) holds bake-ao's
// 8×8 texture in red, and the same green and blue as an export without AO; the other materials
// (no metallic-roughness texture in the file) get bake-ao's own occlusion textures.
TEST_F(Parity, ExportedTextureAoIsTheOrmRedChannel) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  const std::string material = "painted_metal=" + (dir / "pair_a.png").string() + "," + (dir / "pair_b.png").string();
  run_command({"bake-ao", (dir / "showroom.gltf").string(), "-o", (dir / "cli" / "baked.gltf").string(), "--texture", "8",
               "--samples", "16"});
  run_command({"export", (dir / "showroom.gltf").string(), "-o", (dir / "cli" / "plain.gltf").string(), "--material", material});
  run_command({"export", (dir / "showroom.gltf").string(), "-o", (dir / "cli" / "ao.gltf").string(), "--material", material,
               "--ao-texture", "8", "--ao-samples", "16"});
  const auto texels = [&](const char* file, int m, const char* slot) {
    auto doc = gltf::read_document(dir / "cli" / file);
    EXPECT_TRUE(doc);
    const json& material_json = doc->json["materials"][m];
    const json& info = std::string(slot) == "occlusion" ? material_json["occlusionTexture"]
                                                        : material_json["pbrMetallicRoughness"]["metallicRoughnessTexture"];
    const auto bytes = gltf::image_bytes(*doc, doc->json["textures"][info["index"].get<std::size_t>()]["source"].get<std::size_t>());
    EXPECT_TRUE(bytes);
    const auto img = image::decode_image({reinterpret_cast<const unsigned char*>(bytes->data()), bytes->size()}, "t.png",
                                         color::Transfer::linear);
    EXPECT_TRUE(img);
    return *img;
  };
  const image::Image baked = texels("baked.gltf", 0, "occlusion"), plain = texels("plain.gltf", 0, "mr");
  const image::Image orm = texels("ao.gltf", 0, "occlusion"), mr = texels("ao.gltf", 0, "mr");
  ASSERT_EQ(orm.width, 8);
  ASSERT_EQ(orm.channels, 3);
  EXPECT_EQ(mr.pixels, orm.pixels);  // one texture
  for (std::size_t p = 0; p < 64; ++p) {
    EXPECT_EQ(orm.pixels[p * 3], baked.pixels[p]) << p;
    EXPECT_EQ(orm.pixels[p * 3 + 1], plain.pixels[p * std::size_t(plain.channels) + 1]) << p;
    EXPECT_EQ(orm.pixels[p * 3 + 2], plain.pixels[p * std::size_t(plain.channels) + 2]) << p;
  }
  for (int m = 1; m < 5; ++m) EXPECT_EQ(texels("ao.gltf", m, "occlusion").pixels, texels("baked.gltf", m, "occlusion").pixels) << m;
}

// Every PNG a scene gets (export's converted and ORM textures, bake-ao's occlusion textures, a build's
// scene) is written at the requested compression: the zlib header's FLEVEL says stored (level 0) or
// maximum, the stored files are larger, and both decode to the same codes.
TEST_F(Parity, ScenePngsHonourTheCompression) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  const std::string scene = (dir / "showroom.gltf").string();
  const std::string pair = "painted_metal=" + (dir / "pair_a.png").string() + "," + (dir / "pair_b.png").string();
  std::string manifest = "[materials.pair]\npacked = { layout = \"schuler\", files = [\"pair_a.png\", \"pair_b.png\"] }\n"
                         "validate = { enabled = false }\n";
  for (const char* level : {"0", "small"}) {
    const fs::path out = dir / "cli" / level;
    fs::create_directories(out);
    run_command({"export", scene, "-o", (out / "exported.gltf").string(), "--material", pair, "--ao-texture", "8",
                 "--ao-samples", "4", "--png-compression", level});
    run_command({"bake-ao", scene, "-o", (out / "baked.gltf").string(), "--texture", "8", "--samples", "4",
                 "--png-compression", level});
    manifest += std::string("[scenes.s") + level + "]\ninput = \"showroom.gltf\"\noutput = \"" + level +
                "/built.gltf\"\nmaterials = { painted_metal = \"pair\" }\nao = { samples = 4, texture = 8 }\n" +
                "png_compression = " + (level == std::string("0") ? "0" : "\"small\"") + "\n";
  }
  ASSERT_EQ(build(manifest).value("failed", -1), 0);
  const auto flevel = [](const std::string& bytes) {
    const std::size_t idat = bytes.find("IDAT");
    return idat == std::string::npos ? -1 : int(std::uint8_t(bytes[idat + 5]));
  };
  for (const auto& [stored, small] : {std::pair{dir / "cli" / "0", dir / "cli" / "small"}, std::pair{dir / "out" / "0", dir / "out" / "small"}}) {
    std::size_t pngs = 0, stored_bytes = 0, small_bytes = 0;
    for (const auto& e : fs::directory_iterator(stored)) {
      if (e.path().extension() != ".png") continue;
      SCOPED_TRACE(e.path().string());
      ++pngs;
      const fs::path other = small / e.path().filename();
      const std::string a = read_bytes(e.path()), b = read_bytes(other);
      EXPECT_EQ(flevel(a), 0x01);
      EXPECT_EQ(flevel(b), 0xda);
      stored_bytes += a.size(), small_bytes += b.size();
      const RawImage x = read_raw(e.path()), y = read_raw(other);
      EXPECT_GT(x.width, 0);
      EXPECT_EQ(x.samples, y.samples);
    }
    EXPECT_GE(pngs, 5u) << stored;  // converted, ORM and occlusion textures
    EXPECT_GT(stored_bytes, small_bytes);
  }
}

// A misspelt name gets the nearest ones, from the command line as from the manifest.
TEST_F(Parity, UnknownNamesSuggestTheNearest) {
  const RunResult flag = matbake({"export", "in.gltf", "-o", "out.glb", "--ao-sample", "3"});
  EXPECT_EQ(flag.exit_code, 2);
  EXPECT_EQ(flag.err, "matbake: error: unknown option --ao-sample for export; did you mean --ao-samples or --ao-sampler? "
                      "(see matbake --help)\n");
  const RunResult far = matbake({"bake-ao", "in.gltf", "--qwertyuiop"});
  EXPECT_EQ(far.err, "matbake: error: unknown option --qwertyuiop for bake-ao (see matbake --help)\n");
  write_bytes(dir / "assets.toml", "png_compresion = 3\n");
  const RunResult key = matbake({"build", (dir / "assets.toml").string()});
  EXPECT_EQ(key.exit_code, 1);
  EXPECT_EQ(key.err, "matbake: error: " + (dir / "assets.toml").string() +
                         ":1:1: unknown key 'png_compresion' in the manifest; did you mean png_compression?\n");
}

// The manifest's texture keys are checked as the command line's options are.
TEST_F(Parity, ManifestTextureKeysAreChecked) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  for (const auto& [ao, problem] :
       {std::pair{"ao = { texture = 0 }", "assets.toml:4:18: scenes.s.ao.texture: a size such as 1024 or 2048x1024"},
        std::pair{"ao = { texture = \"big\" }", "assets.toml:4:18: scenes.s.ao.texture: a size such as 1024 or 2048x1024"},
        std::pair{"ao = { texture = 64, bits = 12 }", "assets.toml:4:29: scenes.s.ao.bits: 8 or 16"},
        std::pair{"ao = { texture = 64, existing_occlusion = \"add\" }",
                  "assets.toml:4:43: scenes.s.ao.existing_occlusion: use multiply or replace"},
        std::pair{"ao = { padding = 4 }", "assets.toml:4:18: scenes.s.ao.padding applies only with scenes.s.ao.texture as well"},
        std::pair{"ao = { samplez = 4 }", "assets.toml:4:8: unknown key 'samplez' in scenes.s.ao; did you mean samples or sampler?"},
        std::pair{"ao = { samples = 4.5 }", "assets.toml:4:18: scenes.s.ao.samples: an integer expected"},
        std::pair{"ao = { tau = 0 }", "assets.toml:4:14: scenes.s.ao.tau: above 0"}}) {
    write_bytes(dir / "assets.toml", std::string("[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.glb\"\n") + ao + "\n");
    const RunResult r = matbake({"build", (dir / "assets.toml").string()});
    EXPECT_NE(r.exit_code, 0) << ao;
    EXPECT_NE(r.err.find(problem), std::string::npos) << ao << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "s.glb"));
  }
}

// The conflicts a new user met, accepted before with one setting silently winning: refused at both
// doors, each naming both parameters in its own spelling, and nothing written.
TEST_F(Parity, ConflictingSettingsAreRefusedAtBothDoors) {
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  const std::string scene = (dir / "showroom.gltf").string(), out = (dir / "cli" / "s.glb").string();
  const struct {
    std::string keys;
    std::vector<std::string> flags;
    std::string manifest_says, command_line_says;
  } cases[] = {
      {"ao = { samples = 128, texture = 512, into = \"_AO\" }", {"--ao-samples", "128", "--ao-texture", "512", "--ao-into", "_AO"},
       "assets.toml:4:45: scenes.s.ao.into and scenes.s.ao.texture cannot be given together",
       "--ao-into and --ao-texture cannot be given together"},
      {"ao = { relative_distance = 0.3, max_distance = 2.0 }", {"--ao-relative-distance", "0.3", "--ao-max-distance", "2.0"},
       "assets.toml:4:28: scenes.s.ao.relative_distance and scenes.s.ao.max_distance cannot be given together",
       "--ao-relative-distance and --ao-max-distance cannot be given together"},
      {"colour_codec = \"uastc\"\ncolour_quality = 200", {"--colour-codec", "uastc", "--colour-quality", "200"},
       "assets.toml:4:16: scenes.s.colour_codec applies only with scenes.s.texture_format = \"ktx2\"",
       "--colour-codec applies only with --texture-format ktx2"},
      {"texture_format = \"ktx2\"\ncolour_codec = \"uastc\"\ncolour_quality = 200",
       {"--texture-format", "ktx2", "--colour-codec", "uastc", "--colour-quality", "200"},
       "assets.toml:6:18: scenes.s.colour_quality applies only with scenes.s.colour_codec = \"etc1s\"",
       "--colour-quality applies only with --colour-codec etc1s"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.keys);
    write_bytes(dir / "assets.toml", "[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.glb\"\n" + c.keys + "\n");
    const RunResult built = matbake({"build", (dir / "assets.toml").string()});
    EXPECT_EQ(built.exit_code, 1);
    EXPECT_NE(built.err.find(c.manifest_says), std::string::npos) << built.err;
    std::vector<std::string> args = {"export", scene, "-o", out};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    const RunResult exported = matbake(args);
    EXPECT_EQ(exported.exit_code, 2);
    EXPECT_EQ(exported.err, "matbake: error: " + c.command_line_says + "\n");
    EXPECT_FALSE(fs::exists(dir / "out" / "s.glb"));
    EXPECT_FALSE(fs::exists(out));
  }
  // A build's --status builds nothing: a flag about building beside it is refused, not ignored.
  for (const char* flag : {"-n", "--force", "--prune", "--keep-stale"}) {
    const RunResult r = matbake({"build", (dir / "assets.toml").string(), "--status", flag});
    EXPECT_EQ(r.exit_code, 2) << flag;
    EXPECT_NE(r.err.find("excludes --status"), std::string::npos) << r.err;
  }
}

// A misspelt command gets the nearest names as a misspelt flag does; a count out of range is said in words.
TEST(CliMain, AMisspeltCommandOrABadCountIsSaidInWords) {
  EXPECT_EQ(matbake({"buidl", "x.toml"}).err, "matbake: error: unknown command 'buidl'; did you mean build?\n");
  EXPECT_EQ(matbake({"-j", "2", "exprot"}).err, "matbake: error: unknown command 'exprot'; did you mean export?\n");
  const RunResult jobs = matbake({"-j", "-1", "build", "x.toml"});
  EXPECT_EQ(jobs.exit_code, 2);
  EXPECT_EQ(jobs.err, "matbake: error: --jobs: '-1': a count of worker threads, 0 (all cores) or more (see matbake --help)\n");
}

}  // namespace
}  // namespace matbake::test
