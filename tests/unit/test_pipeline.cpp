// The build module's pure parts: manifest parsing (every key reaches its field; errors carry the
// manifest's line and column), plans (inputs, outputs, refusals), depfile escaping, Ninja text,
// and the progress bar's drawing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "cli/progress_bar.hpp"
#include "matbake/cluster.hpp"
#include "matbake/build_progress.hpp"
#include "matbake/pipeline.hpp"
#include "matbake/script_text.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

constexpr const char* kFull = R"(output = "built"
transfer = "gamma2.2"
[validate]
tolerance = 0.2
max_violations = 0.01
[materials.brick]
sources = { kd = "t/brick.png", ks = 0.04, gloss = [0.5] }
layout = "schuler"
format = "tif"
bits = "16"
mapping = "fitted"
[materials.gold]
packed = { layout = "gltf-orm", files = ["a.png", "b.png"] }
transfer = "srgb"
decode = "linear"
reference = "gold"
validate = { max_violations = 0.5, heatmap = true }
[scenes.room]
input = "room.gltf"
output = "sub/room.gltf"
materials = { "Bricks" = "brick" }
match_names = false
dielectric_f0 = "ior"
orm = false
mapping = "walter"
ao = { samples = 32, absolute_distance = 2.5, falloff = "none", into = "_AO", seed = 7, two_sided = true, tau = 2, bias = 1e-4, sampler = "random", recompute_normals = "angle", fast_traversal = true }
[bake]
size = 256
[scenes.hero]
input = "low.glb"
[scenes.hero.bake]
from = "sculpt/high.glb"
maps = ["bent_normal", "thickness", "ao"]
front = 0.5
back = 0.25
absolute_cage = true
green = "directx"
padding = 3
texel_samples = 9
seed = 11
match = "by_name"
front_by_part = { bolt = 0.4, plate_2 = 3 }
udim = true
ao = { samples = 24, relative_distance = 0.5 }
)";

TEST(BuildManifest, EveryKeyReachesItsField) {
  auto m = pipeline::parse_manifest(kFull, "/project/assets.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  EXPECT_EQ(m->folder, fs::path("/project"));
  EXPECT_EQ(m->output, fs::path("/project/built"));
  ASSERT_EQ(m->materials.size(), 2u);
  const pipeline::MaterialSpec& brick = m->materials[0];  // tables are sorted by name
  EXPECT_EQ(brick.name, "brick");
  ASSERT_EQ(brick.sources.size(), 3u);
  EXPECT_EQ(brick.sources[0].name, "gloss");
  EXPECT_EQ(brick.sources[0].constant, std::vector<double>{0.5});
  EXPECT_EQ(brick.sources[1].name, "kd");
  EXPECT_EQ(brick.sources[1].file, fs::path("/project/t/brick.png"));
  EXPECT_EQ(brick.sources[2].constant, std::vector<double>{0.04});
  EXPECT_EQ(brick.options.transfer, color::Transfer::gamma22);  // the manifest's default
  ASSERT_TRUE(brick.layout);
  EXPECT_EQ(brick.layout->reference, "schuler");
  EXPECT_EQ(brick.layout->layout.name, "schuler");
  EXPECT_TRUE(brick.layout->file.empty());  // a preset
  EXPECT_EQ(brick.options.format, "tif");
  EXPECT_EQ(brick.options.bits, image::SampleType::u16);
  EXPECT_DOUBLE_EQ(brick.validation.options.tolerance, 0.2);
  EXPECT_DOUBLE_EQ(brick.validation.options.max_violations, 0.01);
  const pipeline::MaterialSpec& gold = m->materials[1];
  ASSERT_TRUE(gold.packed);
  EXPECT_EQ(gold.packed->reference, "gltf-orm");
  EXPECT_EQ(gold.packed_files, (std::vector<fs::path>{"/project/a.png", "/project/b.png"}));
  EXPECT_EQ(gold.options.transfer, color::Transfer::srgb);
  EXPECT_EQ(gold.options.decode, color::Transfer::linear);
  EXPECT_EQ(gold.reference, "gold");
  EXPECT_DOUBLE_EQ(gold.validation.options.tolerance, 0.2);  // inherited, then overridden key by key
  EXPECT_DOUBLE_EQ(gold.validation.options.max_violations, 0.5);
  EXPECT_TRUE(gold.validation.heatmap);
  ASSERT_EQ(m->scenes.size(), 2u);
  const pipeline::SceneSpec& hero = m->scenes[0];
  ASSERT_TRUE(hero.bake);
  EXPECT_EQ(hero.bake->from, "sculpt/high.glb");
  EXPECT_EQ(hero.bake->high, fs::path("/project/sculpt/high.glb"));
  const bake::Request& r = hero.bake->request;
  EXPECT_EQ(r.bake.maps, (std::vector<bake::Map>{bake::Map::bent_normal, bake::Map::thickness, bake::Map::ao}));
  EXPECT_DOUBLE_EQ(r.bake.front, 0.5);
  EXPECT_DOUBLE_EQ(r.bake.back, 0.25);
  EXPECT_TRUE(r.bake.absolute_distances);
  EXPECT_EQ(r.bake.green, bake::Green::directx);
  EXPECT_EQ(r.texture.width, 256);  // the top level's [bake], a default for each baking scene
  EXPECT_EQ(r.texture.height, 256);
  EXPECT_EQ(r.texture.padding, 3);
  EXPECT_EQ(r.texture.texel_samples, 9);
  EXPECT_EQ(r.bake.seed, 11u);
  EXPECT_EQ(r.bake.front_by_part, (std::map<std::string, double, std::less<>>{{"bolt", 0.4}, {"plate_2", 3.0}}));
  EXPECT_TRUE(r.udim);
  EXPECT_EQ(r.occlusion.options.samples, 24);
  EXPECT_DOUBLE_EQ(r.occlusion.options.relative_distance, 0.5);
  EXPECT_FALSE(m->scenes[1].bake);  // the top level's [bake] alone bakes nothing
  const pipeline::SceneSpec& room = m->scenes[1];
  EXPECT_EQ(room.input, fs::path("/project/room.gltf"));
  EXPECT_EQ(room.output, fs::path("sub/room.gltf"));
  EXPECT_EQ(room.materials.at("Bricks"), "brick");
  EXPECT_FALSE(room.match_names);
  EXPECT_EQ(room.options.dielectric_f0, exporter::DielectricF0::ior);
  EXPECT_FALSE(room.options.pack_orm);
  EXPECT_EQ(room.options.mapping, workflow::RoughnessMapping::walter);
  ASSERT_TRUE(room.options.ao);
  const ao::Options& o = room.options.ao->options;
  EXPECT_EQ(o.samples, 32);
  EXPECT_DOUBLE_EQ(o.absolute_distance, 2.5);
  EXPECT_EQ(o.falloff, ao::Falloff::none);
  EXPECT_EQ(o.seed, 7u);
  EXPECT_TRUE(o.two_sided);  // the default is one-sided
  EXPECT_DOUBLE_EQ(o.tau, 2);
  EXPECT_DOUBLE_EQ(o.bias, 1e-4);
  EXPECT_EQ(o.sampler, ao::Sampler::random);
  EXPECT_EQ(o.recompute_normals, scene::NormalWeighting::angle);
  EXPECT_FALSE(o.watertight);
  EXPECT_EQ(room.options.ao->into, ao::Into::attribute);
}

// A source written as text follows the command line's rule: numbers are a constant, anything else a
// file beside the manifest ("./0.5" for a file of that name).
TEST(BuildManifest, SourceTextIsNumbersOrAFileAsOnTheCommandLine) {
  auto m = pipeline::parse_manifest("[materials.a]\nsources = { gloss = \"0.5\", kd = \"0.9,0.6,0.2\", ks = \"./0.04\" }\n",
                                    "/p/m.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  const auto& sources = m->materials[0].sources;
  EXPECT_EQ(sources[0].constant, std::vector<double>{0.5});
  EXPECT_EQ(sources[1].constant, (std::vector<double>{0.9, 0.6, 0.2}));
  EXPECT_TRUE(sources[2].constant.empty());
  EXPECT_EQ(sources[2].file.lexically_normal(), fs::path("/p/0.04"));
  auto bad = pipeline::parse_manifest("[materials.a]\nsources = { gloss = \"1.5\" }\n", "/p/m.toml");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().to_string(), "/p/m.toml:2:21: materials.a.sources.gloss: '1.5': values are in [0, 1]");
}

// Each bad manifest: the error names the file with line and column and says what is wrong.
TEST(BuildManifest, ErrorsSayWhereAndWhat) {
  struct Case {
    const char* text;
    const char* where;
    const char* says;
  };
  const Case cases[] = {
      {"output = \"o\"\n[materials.a]\nsources = { kd = 0.5 }\nlayot = \"x\"\n", "m.toml:4:1", "unknown key 'layot' in materials.a"},
      {"[materials.a\n", "m.toml:1:", "not valid TOML"},
      {"[materials.a]\nsources = { kd = 0.5 }\nbits = \"12\"\n", "m.toml:3:", "materials.a.bits: use 8, 16, half or float"},
      {"[materials.a]\nsources = { albedo = \"x.png\" }\n", "m.toml:2:", "unknown source 'albedo'"},
      {"[materials.a]\nlayout = \"schuler\"\n", "m.toml:1:", "give sources = {...}, packed = {...} or both"},
      {"[materials.\"../up\"]\nsources = { kd = 0.5 }\n", "m.toml:", "letters, digits"},
      {"[scenes.s]\ninput = \"a.gltf\"\noutput = \"../a.glb\"\n", "m.toml:3:", "inside the output folder"},
      {"[scenes.s]\ninput = \"a.gltf\"\noutput = \"/tmp/a.glb\"\n", "m.toml:3:", "inside the output folder"},
      {"[scenes.s]\ninput = \"a.gltf\"\nao = { samples = 0 }\n", "m.toml:3:", "samples: 1 to"},
      {"[scenes.s]\ninput = \"a.gltf\"\nmaterials = { \"X\" = \"nope\" }\n", "m.toml", "no [materials.nope]"},
      {"[validate]\nmax_violations = 2.0\n[materials.a]\nsources = { kd = 0.5 }\n", "m.toml:2:18", "validate.max_violations: 0 to 1"},
      {"output = 3\n", "m.toml:1:", "output: a string expected"},
      // Constants hold texel values, as on the command line (issue "Hostile input").
      {"[materials.a]\nsources = { kd = 0.5, ks = nan }\n", "m.toml:2:28", "materials.a.sources.ks: values are in [0, 1]"},
      {"[materials.a]\nsources = { kd = inf }\n", "m.toml:2:", "materials.a.sources.kd: values are in [0, 1]"},
      {"[materials.a]\nsources = { ks = -0.5 }\n", "m.toml:2:", "materials.a.sources.ks: values are in [0, 1]"},
      {"[materials.a]\nsources = { kd = [0.5, 1.5, 0.5] }\n", "m.toml:2:", "materials.a.sources.kd: values are in [0, 1]"},
      // A float where an integer goes: refused, never cast (toml++ casts 2e52 to int64 unchecked; fuzzing).
      {"[scenes.s]\ninput = \"a.gltf\"\nao = { samples = 2e52 }\n", "m.toml:3:", "samples: an integer expected"},
      {"", "m.toml", "nothing to build"},
      // A source's table form: a file and one of its channels.
      {"[materials.a]\nsources = { gloss = { file = \"sg.png\", chanel = \"a\" } }\n", "m.toml:2:",
       "unknown key 'chanel' in materials.a.sources.gloss"},
      {"[materials.a]\nsources = { gloss = { file = \"sg.png\", channel = \"alpha\" } }\n", "m.toml:2:50",
       "materials.a.sources.gloss.channel: 'alpha' is not r, g, b, a or rgb"},
      {"[materials.a]\nsources = { gloss = { channel = \"a\" } }\n", "m.toml:2:", "materials.a.sources.gloss: needs file"},
      // Its text form's channel suffix, checked as the table form's is (not a missing file at run time).
      {"[materials.a]\nsources = { gloss = \"sg.png:y\" }\n", "m.toml:2:21",
       "materials.a.sources.gloss: 'sg.png:y': channel 'y' is not r, g, b, a or rgb"},
      {"png_compression = 13\n[materials.a]\nsources = { kd = 0.5 }\n", "m.toml:1:19",
       "manifest.png_compression: fast, default, small or a level 0 to 12"},
      {"[materials.a]\nsources = { kd = 0.5 }\npng_compression = \"quick\"\n", "m.toml:3:", "materials.a.png_compression"},
      {"[materials.a]\nsources = { kd = 0.5 }\npng_compression = 6.0\n", "m.toml:3:19",
       "materials.a.png_compression: an integer or a string expected"},
      // A scene's bake: its high-poly, its maps (a list or the command line's text), its ao table.
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { maps = \"normal\" }\n", "m.toml:3:", "scenes.s.bake: from = \"high.glb\" is required"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", maps = [\"normal\", \"nromal\"] }\n", "m.toml:3:",
       "scenes.s.bake.maps: maps among"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", maps = [\"ao\", 3] }\n", "m.toml:3:",
       "scenes.s.bake.maps: a number, a string, a list of names, a table of numbers or true/false expected"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", match = \"by_name\", back_by_part = { bolt = \"x\" } }\n",
       "m.toml:3:", "scenes.s.bake.back_by_part: a table of numbers by name expected"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", back_by_part = { bolt = 0.5 } }\n", "m.toml:3:",
       "scenes.s.bake.back_by_part"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", match = \"by_name\", back_by_part = {} }\n", "m.toml:3:",
       "scenes.s.bake.back_by_part: a table of numbers by name expected, not an empty one"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", mpas = \"ao\" }\n", "m.toml:3:",
       "unknown key 'mpas' in scenes.s.bake"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", ao = { sample = 3 } }\n", "m.toml:3:",
       "unknown key 'sample' in scenes.s.bake.ao"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", ao = { samples = 0 } }\n", "m.toml:3:",
       "scenes.s.bake.ao.samples: 1 to"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", ao = 3 }\n", "m.toml:3:", "scenes.s.bake.ao must be a table"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = \"h.glb\"\n", "m.toml:3:", "scenes.s.bake must be a table"},
      {"[scenes.s]\ninput = \"a.gltf\"\nao = { samples = 4 }\nbake = { from = \"h.glb\", maps = \"normal,ao\" }\n",
       "m.toml:3:", "the export's ao and the bake's ao map would both make the occlusion"},
      {"[scenes.s]\ninput = \"a.gltf\"\nao = { samples = 4 }\nbake = { from = \"h.glb\", vertex_maps = [\"ao\"] }\n",
       "m.toml:3:", "keep one (drop `ao`, or ao from bake.vertex_maps)"},
      {"[scenes.s]\ninput = \"a.gltf\"\nbake = { from = \"h.glb\", vertex_maps = [\"ao\", \"normal\"] }\n", "m.toml:3:",
       "scenes.s.bake.vertex_maps: vertex maps among ao, thickness, curvature, height"},
  };
  for (const Case& c : cases) {
    auto m = pipeline::parse_manifest(c.text, "m.toml");
    ASSERT_FALSE(m) << c.text;
    EXPECT_EQ(m.error().path.rfind(c.where, 0), 0u) << c.text << "\n→ " << m.error().to_string();
    EXPECT_NE(m.error().message.find(c.says), std::string::npos) << c.text << "\n→ " << m.error().to_string();
    EXPECT_EQ(m.error().to_string().find('\n'), std::string::npos);
  }
  auto missing = pipeline::read_manifest("/nonexistent/m.toml");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().path, "/nonexistent/m.toml");
}

// One entry, a material per file its pattern matches: {name} in its file names, per-name overrides,
// names that cannot name files skipped with a note; clashes and stray overrides are errors.
TEST(BuildManifest, MaterialRulesMakeAMaterialPerMatch) {
  TempDir dir;
  fs::create_directories(dir / "t");
  for (const char* f : {"a_BaseColor.png", "b_BaseColor.png", "bad name_BaseColor.png", "c_Normal.png"}) write_bytes(dir / "t" / f, "");
  const std::string rule = R"([material_rules.lib]
match = "t/{name}_BaseColor.png"
sources = { base_color = "t/{name}_BaseColor.png", roughness = { file = "t/{name}_ORM.png", channel = "g" }, metallic = 0.0 }
layout = "gltf-orm"
reference = "{name}"
[material_rules.lib.overrides.b]
sources = { roughness = 0.3 }
layout = "gltf-metal-rough"
)";
  auto m = pipeline::parse_manifest(rule, dir / "m.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  ASSERT_EQ(m->materials.size(), 2u);
  const pipeline::MaterialSpec& a = m->materials[0];
  EXPECT_EQ(a.name, "a");
  EXPECT_EQ(a.reference, "a");
  EXPECT_EQ(a.layout->reference, "gltf-orm");
  const auto source = [](const pipeline::MaterialSpec& spec, const std::string& name) {
    return *std::find_if(spec.sources.begin(), spec.sources.end(), [&](const pack::SourceInput& s) { return s.name == name; });
  };
  ASSERT_EQ(a.sources.size(), 3u);
  EXPECT_EQ(source(a, "base_color").file, dir / "t/a_BaseColor.png");
  EXPECT_EQ(source(a, "roughness").file, dir / "t/a_ORM.png");
  EXPECT_EQ(source(a, "roughness").channels, pack::FileChannels::g);
  EXPECT_EQ(a.origins.of(""), (dir / "m.toml").string() + ":1:1");  // errors point at the rule
  const pipeline::MaterialSpec& b = m->materials[1];
  EXPECT_EQ(b.layout->reference, "gltf-metal-rough");
  ASSERT_EQ(b.sources.size(), 3u);
  EXPECT_EQ(source(b, "roughness").constant, std::vector<double>{0.3});
  EXPECT_EQ(source(b, "base_color").file, dir / "t/b_BaseColor.png");
  ASSERT_EQ(m->rules.size(), 1u);
  EXPECT_EQ(m->rules[0].materials, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(m->notes.size(), 1u);
  EXPECT_NE(m->notes[0].find("'bad name' is not a material name"), std::string::npos) << m->notes[0];

  const auto error_of = [&](const std::string& text) {
    auto bad = pipeline::parse_manifest(text, dir / "m.toml");
    return bad ? std::string("parsed") : bad.error().to_string();
  };
  EXPECT_NE(error_of("[materials.a]\nsources = { kd = 0.5 }\n" + rule).find("material_rules.lib: 'a' is also a material at "),
            std::string::npos);
  EXPECT_NE(error_of(rule + "[material_rules.lib.overrides.bb]\nlayout = \"schuler\"\n")
                .find("material_rules.lib.overrides.bb: no such match; did you mean b or a?"),
            std::string::npos)
      << error_of(rule + "[material_rules.lib.overrides.bb]\nlayout = \"schuler\"\n");
  EXPECT_NE(error_of(rule + "[material_rules.lib.overrides.renamed]\nlayout = \"schuler\"\n")
                .find("material_rules.lib.overrides.renamed: no such match (its matches now: a, b)"),
            std::string::npos)
      << error_of(rule + "[material_rules.lib.overrides.renamed]\nlayout = \"schuler\"\n");
  // A typo in the pattern (_OMR for _ORM) is an error at its line: it would drop every material the
  // rule made, and the cleaner their outputs.
  EXPECT_EQ(error_of("[material_rules.x]\nmatch = \"t/{name}_OMR.png\"\nsources = { kd = 0.5 }\n"),
            (dir / "m.toml").string() + ":2:9: material_rules.x.match: 't/{name}_OMR.png' matches no file in " + (dir / "t").string());
  EXPECT_EQ(m->rules[0].folder, dir / "t");
  EXPECT_NE(error_of("[material_rules.x]\nmatch = \"t/{name}/BaseColor.png\"\nsources = { kd = 0.5 }\n").find("m.toml:2:9: material_rules.x.match: a file pattern with {name} once"),
            std::string::npos);
  EXPECT_NE(error_of("[material_rules.x]\nmatch = \"t/{name}.png\"\nsources = { kd = 0.5 }\nlayot = 1\n").find("unknown key 'layot' in material_rules.x"),
            std::string::npos);
}

TEST(BuildPlan, JobsWithTheirInputsAndOutputs) {
  TempDir dir;
  GltfBuilder scene;
  const int positions = scene.add_vec3({0, 0, 0, 1, 0, 0, 0, 1, 0});
  scene.add_node({{"mesh", scene.add_mesh(positions)}});
  scene.doc["materials"] = {{{"name", "paint"}}, {{"name", "other"}}};
  scene.doc["images"] = {{{"uri", "tex%20a.png"}}};
  scene.write(dir / "room.gltf", {0});
  write_bytes(dir / "build.toml", R"(
[materials.paint]
sources = { kd = "paint.png", ks = 0.04, gloss = 0.5 }
layout = "gltf-orm"
[materials.unused]
sources = { kd = 0.5 }
validate = { enabled = false }
[materials.scene_only]
sources = { kd = "s.png" }
validate = { enabled = false }
[scenes.room]
input = "room.gltf"
materials = { "other" = "scene_only" }
)");
  auto m = pipeline::read_manifest(dir / "build.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  auto plan = pipeline::make_plan(*m);
  ASSERT_TRUE(plan) << plan.error().to_string();
  // paint: textures + report + ball; unused: no layout, no validation, no scene (a warning);
  // scene_only: nothing of its own (no ball either).
  ASSERT_EQ(plan->jobs.size(), 2u);
  const pipeline::Job& paint = plan->jobs[0];
  EXPECT_EQ(paint.name, "material:paint");
  const fs::path out = dir.path() / "out";
  EXPECT_EQ(paint.outputs.all(), (std::vector<fs::path>{out / "materials/paint_base_color.png", out / "materials/paint_orm.png",
                                                 out / "materials/paint.validation.json", out / "materials/paint_preview.png"}));
  EXPECT_EQ(paint.inputs, std::vector<fs::path>{dir.path() / "paint.png"});
  const pipeline::Job& room = plan->jobs[1];
  EXPECT_EQ(room.name, "scene:room");
  EXPECT_EQ(room.outputs.all(), std::vector<fs::path>{out / "room.glb"});
  // The scene, its image (URI decoded), and the sources of both materials it gets (by name and by the map).
  EXPECT_EQ(room.inputs, (std::vector<fs::path>{dir.path() / "room.gltf", dir.path() / "tex a.png", dir.path() / "s.png",
                                               dir.path() / "paint.png"}));
  EXPECT_EQ(room.materials.size(), 2u);
  EXPECT_EQ(room.materials.at("paint"), 0u);
  ASSERT_EQ(plan->warnings.size(), 1u);
  EXPECT_NE(plan->warnings[0].find("materials.unused"), std::string::npos);
  EXPECT_EQ(plan->state_folder, out / ".matbake");

  // Ninja: one edge per job with its outputs, inputs and depfile, and the regenerate edge.
  const std::string ninja = pipeline::ninja_text(*m, *plan, "/usr/bin/matbake", dir / "build.ninja").value();
  EXPECT_NE(ninja.find("build " + (out / "room.glb").string() + ": matbake " + m->file.string() + " | " + (dir.path() / "room.gltf").string() +
                       " " + (dir.path() / "tex$ a.png").string()),
            std::string::npos)
      << ninja;
  EXPECT_NE(ninja.find("  job = scene:room\n  depfile_path = " + (out / ".matbake/scene-room.d").string()), std::string::npos);
  // The scene's edge waits for its material's (a failed material stops it, as in a build).
  EXPECT_EQ(room.depends_on, std::vector<std::string>{"material:paint"});
  EXPECT_NE(ninja.find((dir.path() / "paint.png").string() + " " + (out / "materials/paint_base_color.png").string() + " " +
                       (out / "materials/paint_orm.png").string() + " " + (out / "materials/paint.validation.json").string() + " " +
                       (out / "materials/paint_preview.png").string() + "\n  job = scene:room"),
            std::string::npos)
      << ninja;
  EXPECT_NE(ninja.find("build build.ninja: matbake_plan " + m->file.string() + "\n"), std::string::npos);
}

TEST(BuildPlan, RefusesToWriteAnInputOrOneFileTwice) {
  TempDir dir;
  write_bytes(dir / "a.toml", "output = \".\"\n[materials.x]\nsources = { kd = \"x.png\" }\nlayout = \"schuler\"\n"
                              "[materials.y]\nsources = { kd = \"materials/x.validation.json\" }\nlayout = \"schuler\"\n");
  auto m = pipeline::read_manifest(dir / "a.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  auto plan = pipeline::make_plan(*m);
  ASSERT_FALSE(plan);
  EXPECT_EQ(plan.error().path, (dir.path() / "materials/x.validation.json").string());
  EXPECT_NE(plan.error().message.find("would overwrite an input"), std::string::npos);

  GltfBuilder scene;
  scene.add_node({{"mesh", scene.add_mesh(scene.add_vec3({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
  scene.write(dir / "s.gltf", {0});
  write_bytes(dir / "b.toml", "[scenes.one]\ninput = \"s.gltf\"\noutput = \"s.glb\"\n"
                              "[scenes.two]\ninput = \"s.gltf\"\noutput = \"s.glb\"\n");
  m = pipeline::read_manifest(dir / "b.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  plan = pipeline::make_plan(*m);
  ASSERT_FALSE(plan);
  EXPECT_NE(plan.error().message.find("written by both scene:one and scene:two"), std::string::npos);
}

// Rewriting a source after a job has written its outputs but before its stamp: the stamp records
// the bytes the job decoded, so the next run rebuilds exactly the jobs built from the older bytes.
TEST(BuildRun, ASourceRewrittenDuringTheRunRebuildsTheJobsThatReadTheOldBytes) {
  TempDir dir;
  write_raw(dir / "kd.png", 4, 4, 3, "uint8", std::vector<double>(48, 100));
  write_raw(dir / "other.png", 4, 4, 3, "uint8", std::vector<double>(48, 30));
  std::string text = "validate = { enabled = false }\n";
  for (const char* name : {"a", "b", "c"}) {
    text += std::string("[materials.") + name + "]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n"
            "layout = \"gltf-orm\"\n";
  }
  text += "[materials.d]\nsources = { base_color = \"other.png\", metallic = 0.0, roughness = 0.5 }\nlayout = \"gltf-orm\"\n";
  write_bytes(dir / "build.toml", text);
  auto m = pipeline::read_manifest(dir / "build.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  auto plan = pipeline::make_plan(*m);
  ASSERT_TRUE(plan) << plan.error().to_string();
  std::atomic<bool> rewritten{false};
  pipeline::RunOptions options;
  options.before_stamp = [&](const pipeline::Job& job) {
    if (job.name != "material:d" && !rewritten.exchange(true)) {
      write_raw(dir / "kd.png", 4, 4, 3, "uint8", std::vector<double>(48, 200));
    }
  };
  auto first = pipeline::run(*m, *plan, options);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->count(pipeline::Outcome::built), 4u);
  EXPECT_GE(first->moved(), 1u);  // at least the job during which it changed says so
  for (const pipeline::JobReport& r : first->jobs) {
    if (!r.moved.empty()) {
      EXPECT_EQ(r.moved, std::vector<fs::path>{dir.path() / "kd.png"});
    }
  }
  // Every job decoded the first bytes (once, shared): all three are out of date, d is not.
  pipeline::RunOptions dry;
  dry.dry_run = true;
  auto check = pipeline::run(*m, *plan, dry);
  ASSERT_TRUE(check);
  for (const pipeline::JobReport& r : check->jobs) {
    if (r.job->name == "material:d") {
      EXPECT_EQ(r.outcome, pipeline::Outcome::up_to_date);
    } else {
      EXPECT_EQ(r.reason, "input changed: " + (dir.path() / "kd.png").string()) << r.job->name;
    }
  }
  auto second = pipeline::run(*m, *plan, {});
  ASSERT_TRUE(second);
  EXPECT_EQ(second->count(pipeline::Outcome::built), 3u);
  EXPECT_EQ(second->moved(), 0u);
  EXPECT_EQ(read_raw(dir / "out/materials/b_base_color.png").samples[0], 200);
}

TEST(BuildDepfile, MakeSyntaxWithEscapes) {
  EXPECT_EQ(pipeline::depfile_text({"/o/a b.png", "/o/c.json"}, {"/in/x#1.png", "/in/$y.png", "/in/z.png"}).value(),
            "/o/a\\ b.png /o/c.json: \\\n  /in/x\\#1.png \\\n  /in/$$y.png \\\n  /in/z.png\n");
}

// A job's work done at a phase: the phases before it whole, its own by the fraction.
TEST(BuildProgress, WorkDoneByPhase) {
  const pipeline::JobWork w{.read = 1, .ao = 2, .textures = 3, .write = 4};
  EXPECT_DOUBLE_EQ(w.total(), 10);
  EXPECT_DOUBLE_EQ(w.done_at(Phase::read, 0), 0);
  EXPECT_DOUBLE_EQ(w.done_at(Phase::textures, 0.5), 4.5);
  EXPECT_DOUBLE_EQ(w.done_at(Phase::write, 2), 10);  // clamped
}

pipeline::Job named_job(const std::string& name) {
  pipeline::Job job;
  job.name = name;
  return job;
}

// The ETA weights each job by its work: with jobs of work 1 and 3, the first done at 2 s is a
// quarter of the build (6 s left), not half (a count of jobs would say 2 s); the second's stage
// counts by its phase.
TEST(BuildProgress, EtaWeightsJobsByTheirWork) {
  using Clock = pipeline::BuildProgress::Clock;
  const Clock::time_point t0{};
  const pipeline::Job a = named_job("material:a"), b = named_job("scene:b");
  pipeline::BuildProgress progress;
  progress.planned({{&a, {.read = 1}}, {&b, {.read = 0.5, .textures = 2.5}}}, t0);
  EXPECT_FALSE(progress.seconds_left(t0).has_value());
  progress.started(a, t0);
  progress.started(b, t0);
  progress.finished(a);
  EXPECT_DOUBLE_EQ(progress.fraction_done(), 0.25);
  EXPECT_DOUBLE_EQ(progress.seconds_left(t0 + std::chrono::seconds(2)).value(), 6);
  progress.stage(b, Phase::textures, "encoding textures 3 of 12", 0.25);
  EXPECT_DOUBLE_EQ(progress.fraction_done(), (1 + 0.5 + 2.5 * 0.25) / 4);
  const std::string line = progress.status_line(t0 + std::chrono::seconds(4), 200);
  EXPECT_EQ(line, "[##########..........] 1/2  53% ETA 0:04  scene:b (encoding textures 3 of 12, 4 s)");
  EXPECT_EQ(progress.status_line(t0 + std::chrono::seconds(4), 40), line.substr(0, 37) + "...");
}

// In a log: a line when each job starts (also one that ended before the log was read), and one at
// least every interval while a job runs, saying its stage and the build's share and ETA.
TEST(BuildProgress, LogSaysWhenAJobStartsAndEveryIntervalWhileItRuns) {
  using Clock = pipeline::BuildProgress::Clock;
  using std::chrono::seconds;
  const Clock::time_point t0{};
  const pipeline::Job a = named_job("material:a"), b = named_job("scene:b");
  pipeline::BuildProgress progress;
  progress.planned({{&a, {.read = 1}}, {&b, {.textures = 3}}}, t0);
  progress.started(a, t0);
  progress.finished(a);
  progress.started(b, t0);
  progress.stage(b, Phase::ao, "AO: 2 textures, 64 rays a texel", 0);
  EXPECT_EQ(progress.log_lines(t0, seconds(10)),
            (std::vector<std::string>{"material:a started (1 of 2)", "scene:b started (2 of 2)"}));
  EXPECT_TRUE(progress.log_lines(t0 + seconds(9), seconds(10)).empty());
  EXPECT_EQ(progress.log_lines(t0 + seconds(10), seconds(10)),
            (std::vector<std::string>{"scene:b running: AO: 2 textures, 64 rays a texel, 10 s; build 25% done, ETA 0:30"}));
  EXPECT_TRUE(progress.log_lines(t0 + seconds(19), seconds(10)).empty());
  EXPECT_EQ(progress.log_lines(t0 + seconds(20), seconds(10)).size(), 1u);
  progress.finished(b);
  EXPECT_TRUE(progress.log_lines(t0 + seconds(40), seconds(10)).empty());
}

std::string read_pipe(int fd) {
  std::string text, chunk(4096, '\0');
  for (ssize_t n; (n = read(fd, chunk.data(), chunk.size())) > 0;) text.append(chunk, 0, std::size_t(n));
  return text;
}

// On a terminal the line is drawn only after half a second and cleared at the end; in a log each
// job's start is a line; quiet draws nothing but messages.
TEST(ProgressBar, DrawsAfterAMomentAndClears) {
  const pipeline::Job a = named_job("material:a");
  for (const auto mode : {cli::ProgressBar::Mode::terminal, cli::ProgressBar::Mode::log, cli::ProgressBar::Mode::quiet}) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    {
      pipeline::BuildProgress progress;
      progress.planned({{&a, {.read = 1}}}, pipeline::BuildProgress::Clock::now());
      cli::ProgressBar bar(progress, mode, fds[1]);
      progress.started(a, pipeline::BuildProgress::Clock::now());
      progress.stage(a, Phase::read, "decoding sources", 0.5);
      std::this_thread::sleep_for(std::chrono::milliseconds(800));
      bar.print_above("a message");
      bar.finish();
    }
    close(fds[1]);
    const std::string text = read_pipe(fds[0]);
    close(fds[0]);
    if (mode == cli::ProgressBar::Mode::terminal) {
      EXPECT_NE(text.find("\r\033[K[##########..........] 0/1  50% ETA 0:0"), std::string::npos) << text;
      EXPECT_NE(text.find("material:a (decoding sources, 0 s)"), std::string::npos) << text;
      EXPECT_NE(text.find("\r\033[Ka message\n"), std::string::npos) << text;
      EXPECT_EQ(text.substr(text.size() - 4), "\r\033[K");
    } else if (mode == cli::ProgressBar::Mode::log) {
      EXPECT_EQ(text, "material:a started (1 of 1)\na message\n");
    } else {
      EXPECT_EQ(text, "a message\n");
    }
  }
}

// The memory model's closed form (docs/cluster.md): 4 bytes a channel a texel of the largest
// source, over the channels a job decodes, makes and writes, 16 bytes a texel of working buffers,
// 32 MiB of program; a scene adds its AO textures, geometry and KTX2 encoders; the request is the
// footprint with a quarter on top, rounded up to 64 MB.
TEST(ClusterMemory, FootprintIsTheModelsClosedForm) {
  TempDir dir;
  write_raw(dir / "base.png", 64, 32, 3, "uint8", std::vector<double>(64 * 32 * 3, 100));
  write_raw(dir / "rough.png", 32, 16, 1, "uint8", std::vector<double>(32 * 16, 100));
  write_bytes(dir / "b.bin", std::string(1000, '\0'));
  write_bytes(dir / "s.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 1000, "uri": "b.bin"}],
    "materials": [{"name": "mr"}], "nodes": [{}, {}]})");
  write_bytes(dir / "h.bin", std::string(2000, '\0'));
  write_bytes(dir / "h.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 2000, "uri": "h.bin"}]})");
  auto m = pipeline::parse_manifest(R"(
[materials.mr]                     # files 3 + 1 channels, maps 3 + 1 + 1, textures 4 + 3
sources = { base_color = "base.png", roughness = "rough.png", metallic = 0.0 }
layout = "gltf-orm"
[materials.sg]                     # files 3, maps 3 + 3 + 1, textures 4 + 3, a conversion's 7
sources = { kd = "base.png", ks = 0.04, gloss = 0.5 }
layout = "gltf-orm"
[scenes.s]                         # mr with a glTF material's 13 texture channels
input = "s.gltf"
texture_format = "ktx2"
ao = { samples = 8, texture = 64, per_instance = true }
[scenes.t]                         # a bake onto s.gltf's one material from a high-poly of 2000 bytes
input = "s.gltf"
output = "t.glb"
match_names = false
bake = { from = "h.gltf", maps = ["normal", "ao", "height", "thickness"], size = 16, texel_samples = 2 }
)", dir / "m.toml");
  ASSERT_TRUE(m) << m.error().to_string();
  auto plan = pipeline::make_plan(*m);
  ASSERT_TRUE(plan) << plan.error().to_string();
  const double texels = 64 * 32, mib = 1024.0 * 1024.0;
  const auto footprint = [&](const std::string& name, int cpus) {
    for (const pipeline::Job& j : plan->jobs) {
      if (j.name == name) return pipeline::job_footprint(j, *m, cpus);
    }
    ADD_FAILURE() << name;
    return pipeline::JobFootprint{};
  };
  const pipeline::JobFootprint mr = footprint("material:mr", 1), sg = footprint("material:sg", 1);
  EXPECT_EQ(mr.program, 32 * mib);
  EXPECT_EQ(mr.images, texels * (4 * (4 + 5 + 7) + 16));
  EXPECT_EQ(sg.images, texels * (4 * (3 + 7 + 7 + 7) + 16));
  EXPECT_EQ(mr.geometry + mr.ao + mr.encoder, 0);
  const pipeline::JobFootprint scene = footprint("scene:s", 2);
  EXPECT_EQ(scene.images, texels * (4 * (4 + 5 + 13) + 16));
  EXPECT_EQ(scene.geometry, 8 * 1000);
  EXPECT_EQ(scene.ao, (1 + 2) * 64 * 64 * 24);          // a material and two placements
  // Its 4 glTF textures decoded (RGBA float), then two encoded at once (the job's cores), each
  // with the source kept to measure its levels against (16 B a texel).
  EXPECT_EQ(scene.encoder, 4 * texels * 16 + 2 * texels * (80 + 16 + 72));
  EXPECT_EQ(footprint("scene:s", 1).encoder, 4 * texels * 16 + texels * (80 + 16 + 72));
  m->scenes.at(0).options.delivery.measure_levels = false;  // no copy kept
  EXPECT_EQ(footprint("scene:s", 1).encoder, 4 * texels * 16 + texels * (80 + 72));

  // The bake: the high-poly's geometry with a BVH each for the cage, AO and thickness; per texel the
  // maps' 6 channels (one material), 2 positions of 20 B and 200 B of sums; the normal map and AO
  // read again by the export as its own images (48 B a texel).
  const pipeline::JobFootprint baking = footprint("scene:t", 1);
  EXPECT_EQ(baking.geometry, 8 * 1000 + 3 * 8 * 2000);
  EXPECT_EQ(baking.ao, 16 * 16 * (6 * 4 + 2 * 20 + 200));
  EXPECT_EQ(baking.images, 2 * 16 * 16 * 48);
  EXPECT_EQ(baking.encoder, 0);

  EXPECT_EQ(pipeline::memory_request_mb({.program = 32 * mib, .images = 200 * mib}), 320);  // 290 → 320
  EXPECT_EQ(pipeline::memory_request_mb({.program = 32 * mib}), 64);                        // 40 → 64
  EXPECT_EQ(pipeline::memory_request_mb({.program = 32 * mib, .encoder = 19.2 * mib}), 64);  // 64 → 64
}

// Quoted words come back from bash unchanged, whatever they hold.
TEST(ShellWord, WordsReadBackUnchanged) {
  const std::vector<std::string> words = {"plain",  "with space", "it's",       "$HOME",     "`id`",  "back\\slash",
                                          "new\nline", "ünïcode",   "*",          "a;b|c&d", "'", "--dependency=afterok:1_0",
                                          "%a",     "\"quoted\"",  "tab\there", ""};
  for (const std::string& w : words) {
    const RunResult r = run("/bin/bash", {"-c", "printf '%s' " + shell_word(w)});
    EXPECT_EQ(r.exit_code, 0) << w;
    EXPECT_EQ(r.out, w) << shell_word(w);
  }
  EXPECT_EQ(shell_word("/abs/path-1.2_x:y=z%a@b+c,d"), "/abs/path-1.2_x:y=z%a@b+c,d");
  EXPECT_EQ(shell_word("it's"), "'it'\\''s'");
}

}  // namespace
}  // namespace matbake::test
