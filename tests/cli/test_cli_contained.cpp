// Issue 69: the surfaces added after the gate (bake, the report page, the encode cache, kept maps,
// ownership, inspect, the supervised encoder) held to the same rules as the rest: outside JSON
// bounded before any recursive reader sees it, every written file checked against every input of
// its command, no write through a link, ownership claimed atomically, caches trusted only by their
// content, inspect reading headers alone, and no encoder outliving matbake.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <signal.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <thread>

#include "lib/src/io/bounded_json.hpp"
#include "lib/src/io/bounded_toml.hpp"
#include "matbake/ktx2.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_builder.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

std::string nested(std::size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

// Files as they are now, to show that a refused run changed none of them.
std::map<fs::path, std::string> contents(const fs::path& folder) {
  std::map<fs::path, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (e.is_regular_file()) out[e.path()] = read_bytes(e.path());
  }
  return out;
}

// The quad z = 0 over [−1, 1]² with UVs, material `material` (its base colour the image file
// `image` when one is named), written to `path` (its buffer a data: URI).
void write_quad(const fs::path& path, const std::string& material, float z = 0, const std::string& image = "") {
  GltfBuilder b;
  const int quad = b.add_mesh(b.add_vec3({-1, -1, z, 1, -1, z, 1, 1, z, -1, 1, z}), b.add_indices({0, 1, 2, 0, 2, 3}), 4,
                              b.add_vec3({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
  auto& primitive = b.doc["meshes"][0]["primitives"][0];
  primitive["attributes"]["TEXCOORD_0"] = b.add_floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2);
  primitive["material"] = 0;
  b.doc["materials"] = {{{"name", material}}};
  if (!image.empty()) {
    b.doc["images"] = {{{"uri", image}}};
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorTexture", {{"index", 0}}}};
  }
  b.write(path, {b.add_node({{"mesh", quad}})});
}

TEST(BoundedJson, DepthIsCountedOutsideStringsInOnePass) {
  EXPECT_EQ(json_depth("{}"), 1u);
  EXPECT_EQ(json_depth("{\"a\": [1, {\"b\": []}]}"), 4u);
  EXPECT_EQ(json_depth("[\"[[[[\", \"\\\"[[\"]"), 1u);  // brackets in strings, an escaped quote
  EXPECT_EQ(json_depth(nested(400000)), 400000u);
  EXPECT_EQ(json_limit_problem(nested(kJsonDepthLimit), 1 << 20), "");
  EXPECT_EQ(json_limit_problem(nested(kJsonDepthLimit + 1), 1 << 20),
            "nests arrays and objects 257 deep, past the 256 levels matbake reads");
  EXPECT_EQ(json_limit_problem("[1, 2]", 4), "holds 6 bytes of JSON, over the 4 matbake reads");
  std::string problem;
  EXPECT_TRUE(parse_bounded_json<nlohmann::json>(nested(300), 1 << 20, problem).is_discarded());
  EXPECT_NE(problem.find("300 deep"), std::string::npos);
  EXPECT_EQ(parse_bounded_json<nlohmann::json>("[[1]]", 1 << 20, problem), nlohmann::json::parse("[[1]]"));
  EXPECT_EQ(problem, "");
}

TEST(BoundedToml, KeysAreCountedOutsideStringsCommentsAndNumbers) {
  EXPECT_EQ(toml_key_depth("").depth, 0u);
  EXPECT_EQ(toml_key_depth("x = 3.14 # a.b.c\n").depth, 1u);
  EXPECT_EQ(toml_key_depth("[a.b]\nc.d = 1\n").depth, 4u);
  EXPECT_EQ(toml_key_depth("[a.b]\nc.d = 1\n").line, 2u);
  EXPECT_EQ(toml_key_depth("\"a.b.c\" = 'x.y'\nt = 1979-05-27T07:32:00.999\n").depth, 1u);
  EXPECT_EQ(toml_key_depth("s = \"\"\"\n.a.b.c.\n\"\"\"\nk = '''\n.x.\n'''\n").depth, 1u);
  EXPECT_EQ(toml_key_depth("[[m.n.o]]\np = { q.r = 1 }\n").depth, 5u);  // inline tables: toml++ bounds them
  EXPECT_EQ(toml_key_depth("[0.0.0]\n1.2 = 3.5\n").depth, 5u);  // keys of digits are keys
  EXPECT_EQ(toml_depth_problem(toml_key_depth("[" + std::string(300, 'a') + "]")), "");
  std::string deep = "a";
  for (int i = 0; i < 300; ++i) deep += ".a";
  EXPECT_EQ(toml_depth_problem(toml_key_depth("x = 1\n[" + deep + "]\n")), "keys nest tables 301 deep, past the 256 levels matbake reads");
}

// A manifest (and a material table) whose header names a table 300,000 deep (of letters, of
// digits): one error line with the line, exit 1 (toml++ frees tables recursively: SIGSEGV).
TEST(Contained, AManifestWhoseKeysNestTablesPastTheLimitIsOneErrorLine) {
  TempDir dir;
  std::string deep = "materials";
  for (int i = 0; i < 300000; ++i) deep += ".a";
  write_bytes(dir / "m.toml", "output = \"out\"\n[" + deep + "]\n");
  for (const char* command : {"build", "inspect"}) {
    const RunResult r = matbake({command, (dir / "m.toml").string()});
    EXPECT_EQ(r.exit_code, 1) << command << ": " << r.err.substr(0, 200);
    expect_one_error_line(r, (dir / "m.toml").string() + ":2", "keys nest tables 300001 deep, past the 256 levels matbake reads");
  }
  std::string digits = "0";  // a key's parts may be digits: not a number's dots
  for (int i = 0; i < 299999; ++i) digits += ".0";
  write_bytes(dir / "table.toml", "[" + digits + "]\n");
  const RunResult r = matbake({"materials", "--table", (dir / "table.toml").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err.substr(0, 200);
  expect_one_error_line(r, (dir / "table.toml").string(), "keys nest tables 300000 deep, past the 256 levels matbake reads (line 1)");
}

// A glTF (text and GLB) nested 20,000 deep in its extras: one error line naming the file and the
// depth from every command that reads it, as input, high-poly or a build's scene (was SIGSEGV).
TEST(Contained, AGltfNestedTwentyThousandDeepIsOneErrorLineForEveryCommand) {
  TempDir dir;
  const std::string text = "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + nested(20000) + "}";
  write_bytes(dir / "deep.gltf", text);
  std::string glb = "glTF";
  const auto u32 = [&](std::uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
  std::string chunk = text;
  chunk.resize((chunk.size() + 3) / 4 * 4, ' ');
  u32(2), u32(std::uint32_t(20 + chunk.size())), u32(std::uint32_t(chunk.size()));
  glb += "JSON" + chunk;
  write_bytes(dir / "deep.glb", glb);
  write_quad(dir / "quad.gltf", "plate");
  const std::string problem = "nests arrays and objects 20001 deep, past the 256 levels matbake reads";
  for (const char* name : {"deep.gltf", "deep.glb"}) {
    const std::string deep = (dir / name).string(), quad = (dir / "quad.gltf").string(), out = (dir / "out/o.glb").string();
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"inspect", deep}, {"export", deep, "-o", out}, {"bake-ao", deep, "-o", out},
          {"bake", deep, "--from", quad, "-o", out}, {"bake", quad, "--from", deep, "-o", out},
          {"bake", quad, "--from", quad, "--cage", deep, "-o", out}}) {
      const RunResult r = matbake(args);
      EXPECT_EQ(r.exit_code, 1) << args[0] << " " << name << ": " << r.err.substr(0, 300);
      expect_one_error_line(r, deep, problem);
    }
    write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"" + std::string(name) + "\"\noutput = \"s.glb\"\n");
    const RunResult build = matbake({"build", (dir / "m.toml").string()});
    EXPECT_EQ(build.exit_code, 1) << name << ": " << build.err.substr(0, 300);
    EXPECT_NE(build.err.find(problem), std::string::npos) << name << ": " << build.err.substr(0, 300);
    const RunResult inspect = matbake({"inspect", (dir / "m.toml").string()});  // reports each job's state
    EXPECT_EQ(inspect.exit_code, 0) << name << ": " << inspect.err.substr(0, 300);
    EXPECT_NE(inspect.out.find(problem), std::string::npos) << name << ": " << inspect.out.substr(0, 300);
    EXPECT_FALSE(fs::exists(dir / "out/o.glb"));
  }
}


// State files nested 400,000 deep (under their size limits): the kept-map index of a scene's bake
// (it crashed every later build of that scene), a stamp, the log of files made and the owner file.
// Each is a warning or ignored, the build rebuilds what it must, exit 0, the same bytes.
TEST(Contained, StateFilesNestedDeepAreReadAsNone) {
  TempDir dir;
  copy_example(dir.path());
  write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.glb\"\n"
                              "bake = { from = \"showroom.gltf\", maps = \"normal\", size = 16 }\n");
  const std::string manifest = (dir / "m.toml").string();
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);
  const std::string built = read_bytes(dir / "out/s.glb");
  const std::string deep = nested(400000);
  // Under "maps" of the right form: the index's reader copies an entry (a recursive copy).
  write_bytes(dir / "out/.matbake/bake/scene-s/kept/maps.json", "{\"form\": 1, \"maps\": {\"normal\": " + deep + "}}");
  RunResult r = matbake({"build", manifest, "--force"});
  EXPECT_EQ(r.exit_code, 0) << r.err.substr(0, 300);
  EXPECT_EQ(read_bytes(dir / "out/s.glb"), built);
  for (const char* state : {"scene-s.json", "made.json", "owner.json"}) {
    write_bytes(dir / "out/.matbake" / state, deep);
    r = matbake({"build", manifest});
    EXPECT_EQ(r.exit_code, 0) << state << ": " << r.err.substr(0, 300);
    EXPECT_NE(r.err.find("nests arrays and objects 400000 deep, past the 256 levels matbake reads"), std::string::npos)
        << state << ": " << r.err.substr(0, 300);
    EXPECT_EQ(read_bytes(dir / "out/s.glb"), built) << state;
  }
}

// bake with a .gltf output beside the high-poly: a high-poly or cage whose buffer is the output's
// .bin, or whose image has a baked map's name, is refused before anything is written, naming the
// file (both were overwritten, exit 0).
TEST(Contained, ABakeNeverWritesOverTheHighPolysOrTheCagesFiles) {
  TempDir dir;
  fs::create_directories(dir / "art");
  write_quad(dir / "low.gltf", "plate");
  const auto external = [&](const fs::path& path, float z) {  // the quad with its buffer as art/baked.bin
    GltfBuilder b;
    b.external_bin = true;
    const int quad = b.add_mesh(b.add_vec3({-1, -1, z, 1, -1, z, 1, 1, z, -1, 1, z}), b.add_indices({0, 1, 2, 0, 2, 3}));
    b.write(dir / "art/baked.gltf", {b.add_node({{"mesh", quad}})});
    fs::rename(dir / "art/baked.gltf", path);
  };
  const std::string out = (dir / "art/baked.gltf").string(), low = (dir / "low.gltf").string();
  const std::vector<std::string> bake = {"bake", low, "-o", out, "--maps", "normal", "--size", "8"};
  const auto run_bake = [&](std::vector<std::string> more) {
    std::vector<std::string> args = bake;
    args.insert(args.end(), more.begin(), more.end());
    return matbake(args);
  };
  external(dir / "art/high.gltf", 0.02f);
  auto before = contents(dir.path());
  RunResult r = run_bake({"--from", (dir / "art/high.gltf").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  expect_one_error_line(r, (dir / "art/baked.bin").string(), "is an input; matbake never overwrites its inputs");
  EXPECT_EQ(contents(dir.path()), before);

  write_quad(dir / "art/high.gltf", "plate", 0.02f);  // its buffer a data: URI now
  fs::remove(dir / "art/baked.bin");
  write_quad(dir / "art/cage_base.gltf", "plate", 0.1f);
  external(dir / "art/cage.gltf", 0.1f);
  before = contents(dir.path());
  r = run_bake({"--from", (dir / "art/high.gltf").string(), "--cage", (dir / "art/cage.gltf").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  expect_one_error_line(r, (dir / "art/baked.bin").string(), "is an input; matbake never overwrites its inputs");
  EXPECT_EQ(contents(dir.path()), before);

  // The high-poly reads an image named as the normal map the bake writes beside its output.
  fs::remove(dir / "art/baked.bin");
  fs::remove(dir / "art/cage.gltf");
  write_raw(dir / "art/baked_plate_normal.png", 2, 2, 3, "uint8", std::vector<double>(12, 7));
  write_quad(dir / "art/high.gltf", "plate", 0.02f, "baked_plate_normal.png");
  before = contents(dir.path());
  r = run_bake({"--from", (dir / "art/high.gltf").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("baked_plate_normal.png"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is an input; matbake never overwrites its inputs"), std::string::npos) << r.err;
  EXPECT_EQ(contents(dir.path()), before);
}

// Two quads whose base colours are images named `a/b` (red) and `a_b` (blue), files beside it.
void write_two_named_images(const fs::path& dir) {
  write_raw(dir / "red.png", 2, 2, 3, "uint8", {255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0});
  write_raw(dir / "blue.png", 2, 2, 3, "uint8", {0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255});
  GltfBuilder b;
  const int uv = b.add_floats({0, 1, 1, 1, 1, 0, 0, 0}, "VEC2", 2), indices = b.add_indices({0, 1, 2, 0, 2, 3});
  std::vector<int> nodes;
  for (int m = 0; m < 2; ++m) {
    const float z = float(m);
    const int mesh = b.add_mesh(b.add_vec3({-1, -1, z, 1, -1, z, 1, 1, z, -1, 1, z}), indices);
    b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
    b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["material"] = m;
    nodes.push_back(b.add_node({{"mesh", mesh}}));
  }
  b.doc["images"] = {{{"uri", "red.png"}, {"name", "a/b"}}, {{"uri", "blue.png"}, {"name", "a_b"}}};
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}},
                        {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}}};
  b.write(dir / "two.gltf", nodes);
}

// The report page's copies of a scene's images: each image its own file (`a/b` and `a_b` were one
// file, one picture shown for both), and never through a link (a link as the scene's folder of
// copies sent them outside the output folder).
TEST(Contained, TheReportPageCopiesEachImageToItsOwnFileThroughTheGate) {
  TempDir dir;
  write_two_named_images(dir.path());
  write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"two.gltf\"\noutput = \"s.gltf\"\n");
  const std::string manifest = (dir / "m.toml").string();
  RunResult r = matbake({"build", manifest, "--report"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path copies = dir / "out/report/scene_s";
  EXPECT_EQ(list_folder(copies), (std::vector<std::string>{"a_b-2.png", "a_b.png"}));
  EXPECT_EQ(read_bytes(copies / "a_b.png"), read_bytes(dir / "red.png"));
  EXPECT_EQ(read_bytes(copies / "a_b-2.png"), read_bytes(dir / "blue.png"));
  const std::string page = read_bytes(dir / "out/report.html");
  EXPECT_NE(page.find("report/scene_s/a_b.png"), std::string::npos);
  EXPECT_NE(page.find("report/scene_s/a_b-2.png"), std::string::npos);

  fs::remove_all(copies);
  fs::create_directories(dir / "elsewhere");
  fs::create_directory_symlink(dir / "elsewhere", copies);
  r = matbake({"build", manifest, "--report"});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("leaves the output folder (a link on the way)"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir / "elsewhere"));
}

// A recorded summary whose fields hold other JSON types (anyone may edit a stamp) is read as absent:
// the page is written, exit 0 (it failed with "internal error: [json.exception...]").
TEST(Contained, ARecordedSummaryOfAnotherTypeIsReadAsAbsent) {
  TempDir dir;
  write_two_named_images(dir.path());
  write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"two.gltf\"\noutput = \"s.glb\"\n");
  const std::string manifest = (dir / "m.toml").string();
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);
  const fs::path stamp = dir / "out/.matbake/scene-s.json";
  const nlohmann::json original = nlohmann::json::parse(read_bytes(stamp));
  ASSERT_TRUE(original["summary"]["details"].is_object());
  for (const nlohmann::json& details :
       {nlohmann::json(7), nlohmann::json::array({1}), nlohmann::json{{"textures", 3}}, nlohmann::json{{"textures", {{{"class", 5}}}}},
        nlohmann::json{{"ao_textures", {{{"file", 1}, {"name", nullptr}}}}}, nlohmann::json{{"validation", "x"}}}) {
    nlohmann::json edited = original;
    edited["summary"]["details"] = details;
    write_bytes(stamp, edited.dump());
    const RunResult r = matbake({"build", manifest, "--report"});
    EXPECT_EQ(r.exit_code, 0) << details.dump() << ": " << r.err;
    EXPECT_TRUE(fs::exists(dir / "out/report.html")) << details.dump();
    fs::remove(dir / "out/report.html");
  }
}

// Manifests started at one moment into a fresh folder: exactly one becomes its owner, the others
// are refused naming it (each passed the check and one removed the other's outputs, exit 0). The
// window between reading the owner and recording one is widened by a shim that delays the rename
// onto owner.json (tests/support/slow_rename.cpp); ASan is told the preload is meant.
TEST(Contained, ManifestsStartedTogetherIntoOneFolderLeaveOneOwner) {
  TempDir dir;
  write_raw(dir / "kd.png", 2, 2, 3, "uint8", {100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210});
  for (const char* m : {"a", "b", "c"}) {
    write_bytes(dir / (std::string(m) + ".toml"), "output = \"out\"\n[materials." + std::string(m) +
                                                      "]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n");
  }
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::vector<std::string> env = {std::string("LD_PRELOAD=") + MATBAKE_SLOW_RENAME,
                                        "ASAN_OPTIONS=" + std::string(asan ? asan : "") + ":verify_asan_link_order=0"};
  for (int trial = 0; trial < 2; ++trial) {
    fs::remove_all(dir / "out");
    std::string command;
    for (const char* m : {"a", "b", "c"}) {
      command += "'" + matbake_exe() + "' build '" + (dir / (std::string(m) + ".toml")).string() + "' 2>'" +
                 (dir / (std::string(m) + ".err")).string() + "' >/dev/null & p" + m + "=$!; ";
    }
    command += "wait $pa; echo $?; wait $pb; echo $?; wait $pc; echo $?";
    const RunResult r = run("/bin/bash", {"-c", command}, env);
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '0'), 1) << "trial " << trial << ": exits " << r.out;
    int refused = 0;
    for (const char* m : {"a", "b", "c"}) refused += read_bytes(dir / (std::string(m) + ".err")).find("belongs to") != std::string::npos;
    EXPECT_EQ(refused, 2) << "trial " << trial;
  }
}

// Two shared_output manifests that make one file are refused at planning, naming both manifests
// and the file (they overwrote each other and rebuilt on every run, exit 0).
TEST(Contained, SharedOutputManifestsMakingOneFileAreRefused) {
  TempDir dir;
  write_raw(dir / "kd.png", 2, 2, 3, "uint8", {100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210});
  for (const char* m : {"a", "b"}) {
    write_bytes(dir / (std::string(m) + ".toml"), "shared_output = true\noutput = \"out\"\n[materials.wood]\n"
                                                  "sources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n");
  }
  ASSERT_EQ(matbake({"build", (dir / "a.toml").string()}).exit_code, 0);
  const auto before = contents(dir / "out");
  const RunResult r = matbake({"build", (dir / "b.toml").string()});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  expect_one_error_line(r, (dir / "b.toml").string(), "makes " + (dir / "out/materials/wood").string());
  EXPECT_NE(r.err.find(", which " + (dir / "a.toml").string() + " also makes in the shared output folder"), std::string::npos) << r.err;
  for (const auto& [file, bytes] : before) {
    if (file.string().find("/.matbake/") == std::string::npos) {
      EXPECT_EQ(read_bytes(file), bytes) << file;
    }
  }
  EXPECT_NE(matbake({"build", (dir / "a.toml").string()}).out.find("nothing to do"), std::string::npos);
}

// Encode-cache entries swapped for each other (each a well-formed entry of the right size, under
// another texture's key): both are made again and reported, the delivered bytes are the uncached
// ones (the swapped textures were delivered, exit 0).
TEST(Contained, AnEncodeCacheEntryIsUsedOnlyWhenItsContentIsItsKeys) {
  TempDir dir;
  copy_example(dir.path());
  std::string manifest = read_bytes(dir / "showroom.toml");
  const std::string ao = "samples = 128, relative_distance = 0.25, texture = 256";
  manifest.replace(manifest.find(ao), ao.size(), "samples = 8, relative_distance = 0.25, texture = 64");
  write_bytes(dir / "showroom.toml", manifest + "texture_format = \"png\"\ncolour_max_size = 64\ndata_max_size = 64\n");
  const std::string path = (dir / "showroom.toml").string();
  ASSERT_EQ(matbake({"build", path}).exit_code, 0);
  const std::string built = read_bytes(dir / "out/showroom.glb");
  // Two entries of one size (their PNGs' IHDR alike): the only check was the size.
  std::map<std::string, std::vector<fs::path>> by_size;
  for (const auto& e : fs::directory_iterator(dir / "out/.matbake/encode-cache")) {
    const std::string bytes = read_bytes(e.path());
    by_size[bytes.substr(bytes.find("IHDR"), 12)].push_back(e.path());
  }
  const auto pair = std::find_if(by_size.begin(), by_size.end(), [](const auto& s) { return s.second.size() >= 2; });
  ASSERT_NE(pair, by_size.end());
  const std::vector<fs::path>& entries = pair->second;
  const std::string first = read_bytes(entries[0]);
  write_bytes(entries[0], read_bytes(entries[1]));
  write_bytes(entries[1], first);
  const RunResult r = matbake({"--json", "build", path, "--force"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_bytes(dir / "out/showroom.glb"), built) << r.out;
  int rejected = 0;
  const nlohmann::json report = nlohmann::json::parse(r.out);  // named: a range over a temporary's member dangles
  for (const nlohmann::json& job : report["jobs"]) {
    for (const nlohmann::json& t : job.value("details", nlohmann::json::object()).value("textures", nlohmann::json::array())) {
      rejected += t.value("cache_rejected", false) ? 1 : 0;
    }
  }
  EXPECT_EQ(rejected, 2);
}

// inspect of a 512 MB KTX2 file and of a glTF whose image is a 512 MB PNG: headers only, memory
// independent of the file's size (it read the whole file: 525 MB). The files are sparse; each is
// inspected small first, and growing it to 512 MB may cost at most 16 MB more (under 64 MB in all)
// in the release build. Under the sanitizers the 4 MiB head of an image and its copies stay in
// ASan's quarantine after they are freed (+25 to +32 MB measured): 64 MB more there, far from 512.
TEST(Contained, InspectReadsHeadersAloneWhateverTheFilesSize) {
  TempDir dir;
  constexpr std::uintmax_t kHuge = std::uintmax_t(512) << 20;
  ktx2::UastcFile file{.width = 4, .height = 4};
  auto level = ktx2::uastc_level(std::vector<unsigned char>(16, 0), 0);
  ASSERT_TRUE(level);
  file.levels.push_back(*level);
  auto bytes = ktx2::write_uastc(file);
  ASSERT_TRUE(bytes);
  write_bytes(dir / "huge.ktx2", std::string(bytes->begin(), bytes->end()));
  write_raw(dir / "huge.png", 4, 4, 3, "uint8", std::vector<double>(48, 9));
  write_quad(dir / "quad.gltf", "plate", 0, "huge.png");
  const auto inspect = [&](const char* name) {
    return run_measured(matbake_exe(), {"--json", "inspect", (dir / name).string()}, matbake_environment());
  };
  const double small_ktx2 = inspect("huge.ktx2").peak_mb, small_gltf = inspect("quad.gltf").peak_mb;
  fs::resize_file(dir / "huge.ktx2", kHuge);
  fs::resize_file(dir / "huge.png", kHuge);
  for (const char* name : {"huge.ktx2", "quad.gltf"}) {
    const RunResult r = inspect(name);
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
#ifdef MATBAKE_SANITIZED
    constexpr double kMoreMb = 64;
#else
    constexpr double kMoreMb = 16;
    EXPECT_LT(r.peak_mb, 64) << name;
#endif
    EXPECT_LT(r.peak_mb, (std::string(name) == "huge.ktx2" ? small_ktx2 : small_gltf) + kMoreMb) << name;
    const nlohmann::json report = nlohmann::json::parse(r.out)["inspected"];
    const nlohmann::json& facts = std::string(name) == "huge.ktx2" ? report : report["images"][0];
    EXPECT_EQ(facts["bytes"], kHuge) << name;
  }
}

// An encoder wrapper that starts basisu without exec (here `sleep`), in its own group, in another
// (`set -m`) or in a session of its own (setsid): kill -9 of matbake takes the wrapper's child with
// it (it ran to its end). One that leaves a folder where its output file
// should be: the run fails and leaves no temporary folder in the output folder (one stayed for good).
TEST(Contained, NoEncoderDescendantOutlivesMatbakeAndNoTemporaryFolderStays) {
  TempDir dir;
  write_quad(dir / "quad.gltf", "plate", 0, "c.png");
  write_raw(dir / "c.png", 4, 4, 3, "uint8", std::vector<double>(48, 90));
  const fs::path wrapper = dir / "basisu";
  write_bytes(wrapper, "#!/bin/bash\n"
                       "if [ \"$1\" = -version ]; then echo 'Basis Universal GPU Texture Compressor v1.16.4'; exit 0; fi\n"
                       "case $MODE in\n"
                       "  child) sleep 1000 & echo $! > \"$CHILDPID\"; wait ;;\n"
                       "  jobs) set -m; sleep 1000 & echo $! > \"$CHILDPID\"; wait ;;\n"
                       "  session) setsid sleep 1000 & echo $! > \"$CHILDPID\"; wait ;;\n"
                       "  folder) while [ $# -gt 0 ]; do [ \"$1\" = -output_path ] && { out=$2; shift; }; last=$1; shift; done\n"
                       "          mkdir -p \"$out/$(basename \"$last\" .png).ktx2/inside\"; exit 0 ;;\n"
                       "esac\n");
  fs::permissions(wrapper, fs::perms::owner_exec, fs::perm_options::add);
  const std::string childpid = (dir / "child").string(), out = (dir / "out/q.glb").string();
  for (const std::string mode : {"child", "jobs", "session"}) {  // in its group; its own group (set -m); its own session
    fs::remove(childpid);
    const std::string command = "MATBAKE_BASISU='" + wrapper.string() + "' CHILDPID='" + childpid + "' MODE=" + mode + " '" +
                                matbake_exe() + "' export '" + (dir / "quad.gltf").string() + "' -o '" + out +
                                "' --texture-format ktx2 >/dev/null 2>&1 & m=$!; for i in $(seq 100); do [ -s '" + childpid +
                                "' ] && break; sleep 0.1; done; kill -KILL $m; wait $m; echo $?";
    const RunResult r = run("/bin/bash", {"-c", command}, matbake_environment());
    EXPECT_EQ(r.out, "137\n") << mode << ": " << r.err;
    const std::string pid = read_bytes(childpid).substr(0, read_bytes(childpid).find('\n'));
    const auto runs = [&] { return fs::exists("/proc/" + pid) && read_bytes("/proc/" + pid + "/stat").find(") Z") == std::string::npos; };
    for (int i = 0; i < 100 && runs(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_FALSE(runs()) << mode << ": the wrapper's child " << pid << " outlived matbake";
    if (runs()) ::kill(std::stoi(pid), SIGKILL);
  }

  fs::remove_all(dir / "out");
  const RunResult folder = matbake({"export", (dir / "quad.gltf").string(), "-o", out, "--texture-format", "ktx2"},
                                   {"MATBAKE_BASISU=" + wrapper.string(), "MODE=folder"});
  EXPECT_EQ(folder.exit_code, 1) << folder.err;
  EXPECT_TRUE(!fs::exists(dir / "out") || list_folder(dir / "out").empty()) << (fs::exists(dir / "out") ? list_folder(dir / "out")[0] : "");
}

}  // namespace
}  // namespace matbake::test
