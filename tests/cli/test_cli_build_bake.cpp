// A manifest scene's bake (`bake = { from, maps, ... }`) through `matbake build`: what it writes, and
// that it is incremental per map: the parameters a map reads decide whether it is traced again,
// kept maps are checked before they are trusted, and a rebuild gives the bytes of a fresh build.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <map>
#include <set>

#include "lib/src/gltf/document.hpp"
#include "matbake/image.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The example's scene baked onto itself (no ../shared needed): the cage finds the same surface, so
// the normal map is flat and the height zero; what matters here is what is traced and written.
std::string manifest_text(const std::string& output, const std::string& maps, int ao_samples, const std::string& more = "") {
  return "output = \"" + output + "\"\n[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.glb\"\n" + more +
         "bake = { from = \"showroom.gltf\", maps = " + maps + ", size = 32, texel_samples = 2, ao = { samples = " +
         std::to_string(ao_samples) + " } }\n";
}

struct Built {
  json job;  // the scene job's report
  std::map<std::string, std::string> files;  // what the build wrote, by name, with its bytes
};

Built build(const fs::path& dir, const std::string& output, const std::string& maps, int ao_samples,
            const std::string& manifest = "m.toml", const std::string& more = "") {
  write_bytes(dir / manifest, manifest_text(output, maps, ao_samples, more));
  const RunResult r = matbake({"--json", "build", (dir / manifest).string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const json report = json::parse(r.out, nullptr, false);
  Built out;
  if (report.is_object() && report["jobs"].size() == 1) out.job = report["jobs"][0];
  for (const auto& e : fs::directory_iterator(dir / output)) {
    if (e.is_regular_file()) out.files[e.path().filename().string()] = read_bytes(e.path());
  }
  return out;
}

// The names of the files that differ between two builds (or are in one only).
std::vector<std::string> differing(const Built& a, const Built& b) {
  std::vector<std::string> names;
  for (const auto& [name, bytes] : a.files) {
    if (!b.files.count(name) || b.files.at(name) != bytes) names.push_back(name);
  }
  for (const auto& [name, bytes] : b.files) {
    if (!a.files.count(name)) names.push_back(name);
  }
  return names;
}

std::vector<std::string> reused(const Built& b) { return b.job["details"]["bake"]["reused"].get<std::vector<std::string>>(); }

TEST(CliBuildBake, ASceneIsBakedThenExportedAndOnlyWhatAChangeDecidesIsTracedAgain) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  const std::string maps = "[\"normal\", \"ao\", \"height\"]";
  const Built first = build(dir.path(), "out", maps, 4);
  EXPECT_EQ(first.job["outcome"], "built");
  EXPECT_EQ(first.job["details"]["bake"]["textures"].size(), 5u);  // five materials
  EXPECT_TRUE(reused(first).empty());
  // The normal map and AO are the materials' own textures (with TANGENT written); height beside.
  {
    const auto doc = gltf::read_document(dir / "out/s.glb");
    ASSERT_TRUE(doc) << doc.error().to_string();
    for (const auto& m : doc->json["materials"]) {
      EXPECT_TRUE(m.contains("normalTexture") && m.contains("occlusionTexture")) << m.dump();
    }
    for (const auto& mesh : doc->json["meshes"]) {
      for (const auto& p : mesh["primitives"]) EXPECT_TRUE(p["attributes"].contains("TANGENT"));
    }
  }
  EXPECT_EQ(first.files.count("s_wood_height.exr"), 1u);
  EXPECT_EQ(first.files.size(), 6u);  // the scene and five height maps: nothing of the bake's own work
  MATBAKE_VALIDATE_OR_SKIP(report, dir / "out/s.glb");
  EXPECT_EQ(report->errors, 0) << report->summary;
  EXPECT_EQ(report->warnings, 0) << report->summary;

  // Up to date: nothing runs.
  const RunResult again = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(again.out, "nothing to do: 1 jobs up to date\n") << again.err;

  // The AO's samples alone: AO is traced again, normal and height are read back, and the bytes are
  // those of a fresh build with the new samples.
  const Built ao8 = build(dir.path(), "out", maps, 8);
  EXPECT_EQ(ao8.job["reason"], "its options changed: bake.ao.samples 4 → 8");
  EXPECT_EQ(reused(ao8), (std::vector<std::string>{"normal", "height"}));
  const Built fresh8 = build(dir.path(), "fresh", maps, 8, "fresh.toml");
  EXPECT_TRUE(reused(fresh8).empty());
  EXPECT_TRUE(differing(ao8, fresh8).empty()) << differing(ao8, fresh8).front();
  EXPECT_EQ(differing(ao8, first), std::vector<std::string>{"s.glb"});  // the AO differs, the heights do not

  // A kept map that is not as it was kept (same size, other bytes) is traced again, never trusted.
  const fs::path kept = dir / "out/.matbake/bake/scene-s/kept/0_normal.f32";
  ASSERT_TRUE(fs::exists(kept));
  write_bytes(kept, std::string(read_bytes(kept).size(), '\0'));  // every normal (0, 0, 0)
  write_bytes(dir / "out/.matbake/bake/scene-s/kept/maps.json.tmp", "not mine");  // a stray file: ignored
  const Built ao4 = build(dir.path(), "out", maps, 4);
  EXPECT_EQ(reused(ao4), (std::vector<std::string>{"height"}));
  EXPECT_TRUE(differing(ao4, first).empty()) << differing(ao4, first).front();

  // A garbled index: everything traced again.
  write_bytes(dir / "out/.matbake/bake/scene-s/kept/maps.json", "{\"form\": 1, \"maps\": {\"normal\": 7}");
  const Built garbled = build(dir.path(), "out", maps, 8);
  EXPECT_TRUE(reused(garbled).empty());
  EXPECT_TRUE(differing(garbled, fresh8).empty()) << differing(garbled, fresh8).front();
  // An index of the wrong shape (JSON, but `maps` a number): the same (it failed the job before).
  write_bytes(dir / "out/.matbake/bake/scene-s/kept/maps.json", "{\"form\": 1, \"maps\": 3, \"trace\": []}");
  const Built shaped = build(dir.path(), "out", maps, 4);
  EXPECT_TRUE(reused(shaped).empty());
  EXPECT_TRUE(differing(shaped, first).empty()) << differing(shaped, first).front();
  EXPECT_EQ(reused(build(dir.path(), "out", maps, 8)), (std::vector<std::string>{"normal", "height"}));

  // A change to the high-poly (here also the low-poly) traces every map again.
  write_bytes(dir / "showroom.gltf", read_bytes(dir / "showroom.gltf") + " ");
  const Built changed = build(dir.path(), "out", maps, 8);
  EXPECT_EQ(changed.job["reason"].get<std::string>().rfind("input changed", 0), 0u) << changed.job.dump();
  EXPECT_TRUE(reused(changed).empty());

  // A map dropped: its files are stale and removed; the others are read back.
  const Built dropped = build(dir.path(), "out", "[\"normal\", \"ao\"]", 8);
  EXPECT_EQ(reused(dropped), (std::vector<std::string>{"normal", "ao"}));
  EXPECT_EQ(dropped.files.size(), 1u) << "the height maps are stale";

  // An export parameter alone: nothing is traced, every map is read back, and the report gives the
  // cage and the counts of the trace they were kept from: its rays and misses, not zeros (a CI gate
  // on misses reads them).
  const Built export_only = build(dir.path(), "out", "[\"normal\", \"ao\"]", 8, "m.toml", "png_compression = 1\n");
  EXPECT_EQ(reused(export_only), (std::vector<std::string>{"normal", "ao"}));
  const json& kept_report = export_only.job["details"]["bake"];
  const json& traced_report = changed.job["details"]["bake"];  // the trace kept (the example as changed)
  EXPECT_GT(traced_report["front"].get<double>(), 0);
  EXPECT_EQ(kept_report["front"], traced_report["front"]);
  EXPECT_EQ(kept_report["back"], traced_report["back"]);
  for (std::size_t t = 0; t < 5; ++t) {
    for (const char* count : {"texels", "missed_texels", "padded", "rays", "misses", "from_inside"}) {
      EXPECT_EQ(kept_report["textures"][t][count], traced_report["textures"][t][count]) << t << " " << count;
    }
  }
  EXPECT_GT(kept_report["textures"][2]["rays"].get<std::size_t>(), 0u);
}

// A cage mesh is an input of the scene's job: a change to it rebuilds the scene and traces every map.
TEST(CliBuildBake, ACageMeshIsAnInputOfTheBake) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  fs::copy_file(kExamples / "showroom.gltf", dir / "cage.gltf");  // the low-poly itself: rays along its normals
  const std::string maps = "[\"normal\"], cage = \"cage.gltf\"";
  const Built first = build(dir.path(), "out", maps, 4);
  EXPECT_EQ(first.job["outcome"], "built");
  // The cage touches the low-poly everywhere: the extrusion's rays (along each face's own normal).
  const Built plain = build(dir.path(), "plain", "[\"normal\"], average_normals = false", 4, "plain.toml");
  EXPECT_EQ(first.job["details"]["bake"]["front"], plain.job["details"]["bake"]["front"]);
  EXPECT_TRUE(differing(first, plain).empty());
  EXPECT_EQ(first.job["details"]["bake"]["textures"][0]["misses"], 0);
  write_bytes(dir / "cage.gltf", read_bytes(dir / "cage.gltf") + " ");
  const Built changed = build(dir.path(), "out", maps, 4);
  EXPECT_NE(changed.job["reason"].get<std::string>().find("cage.gltf"), std::string::npos) << changed.job.dump();
  EXPECT_TRUE(reused(changed).empty());
  EXPECT_TRUE(differing(changed, first).empty());
}

// Vertex maps through a build: attributes on every primitive of the exported scene (AO as COLOR_0
// here), validator-clean; a change to them alone traces only the vertices, reading every texture
// map back (their keys do not hold the vertex parameters).
TEST(CliBuildBake, VertexMapsReachTheExportedSceneAndAChangeToThemReadsTheTexturesBack) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  // vertex_ao_into with AO among the vertex maps only (it is refused without: it would do nothing).
  const auto run = [&](const std::string& vertex_maps) {
    const std::string into = vertex_maps.find("ao") != std::string::npos ? ", vertex_ao_into = \"COLOR_0\"" : "";
    write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.glb\"\n"
                                "bake = { from = \"showroom.gltf\", maps = [\"normal\", \"ao\"], size = 16, vertex_maps = \"" +
                                    vertex_maps + "\"" + into + ", ao = { samples = 4 } }\n");
    const RunResult r = matbake({"--json", "build", (dir / "m.toml").string()});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return json::parse(r.out, nullptr, false)["jobs"][0];
  };
  const json first = run("curvature,ao");
  EXPECT_EQ(first["details"]["bake"]["reused"], json::array());
  EXPECT_EQ(first["details"]["bake"]["vertices"]["attributes"], json({"_CURVATURE", "COLOR_0"}));
  const auto attributes_of_every_primitive = [&] {
    std::set<std::string> common;
    const json doc = gltf::read_document(dir / "out/s.glb")->json;
    bool first_primitive = true;
    for (const auto& mesh : doc["meshes"]) {
      for (const auto& primitive : mesh["primitives"]) {
        std::set<std::string> names;
        for (const auto& [name, accessor] : primitive["attributes"].items()) names.insert(name);
        if (first_primitive) common = names;
        std::erase_if(common, [&](const std::string& n) { return !names.count(n); });
        first_primitive = false;
      }
    }
    return common;
  };
  EXPECT_TRUE(attributes_of_every_primitive().count("_CURVATURE"));
  EXPECT_TRUE(attributes_of_every_primitive().count("COLOR_0"));
  MATBAKE_VALIDATE_OR_SKIP(report, dir / "out/s.glb");
  EXPECT_EQ(report->errors, 0) << report->summary;

  const json second = run("curvature");
  EXPECT_EQ(second["outcome"], "built");
  EXPECT_EQ(second["details"]["bake"]["reused"], json({"normal", "ao"}));
  EXPECT_FALSE(attributes_of_every_primitive().count("COLOR_0"));
}

TEST(CliBuildBake, BadBakesFailTheirJobNamingTheManifestsLine) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  // No such high-poly: the job fails at planning, naming the key's line.
  write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"showroom.gltf\"\nbake = { from = \"nope.glb\" }\n");
  RunResult r = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((dir / "m.toml").string() + ":4:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scenes.s.bake.from"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nope.glb"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/s.glb"));

  // No such cage mesh: the same, naming its key.
  write_bytes(dir / "m.toml", "output = \"out\"\n[scenes.s]\ninput = \"showroom.gltf\"\n"
                              "bake = { from = \"showroom.gltf\", cage = \"cage.glb\" }\n");
  r = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((dir / "m.toml").string() + ":4:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("scenes.s.bake.cage"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/s.glb"));

  // A manifest material with its own occlusion given to a baked material would replace the baked
  // AO: refused, naming both.
  write_bytes(dir / "m.toml", "output = \"out\"\n[materials.wood]\nsources = { base_color = 0.5, metallic = 0, roughness = 0.5, occlusion = 0.8 }\n"
                              "[scenes.s]\ninput = \"showroom.gltf\"\nbake = { from = \"showroom.gltf\", maps = \"ao\", size = 16 }\n");
  r = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("glTF material 'wood' is baked and also given a manifest material"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/s.glb"));
}

// A manifest material without occlusion of its own, given to a material the bake puts AO on: its
// metal-rough maps (here constants: factors) replace the material's, the baked AO stays its
// occlusionTexture (it was refused). The scene's other materials keep theirs.
TEST(CliBuildBake, BakedAoStaysWithAManifestMaterialWithoutOcclusion) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  const std::string bake = "[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.gltf\"\n"
                           "bake = { from = \"showroom.gltf\", maps = \"ao\", size = 16, ao = { samples = 8 } }\n";
  write_bytes(dir / "alone.toml", "output = \"alone\"\n" + bake);
  RunResult r = matbake({"build", (dir / "alone.toml").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  write_bytes(dir / "m.toml", "output = \"out\"\n[materials.wood]\nsources = { base_color = 0.5, metallic = 0.25, roughness = 0.75 }\n" + bake);
  r = matbake({"build", (dir / "m.toml").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto alone = gltf::read_document(dir / "alone/s.gltf");
  const auto given = gltf::read_document(dir / "out/s.gltf");
  ASSERT_TRUE(alone && given);
  // A material's occlusion image, decoded.
  const auto occlusion = [](const gltf::Document& doc, std::size_t m) -> std::vector<float> {
    const auto& material = doc.json["materials"][m];
    if (!material.contains("occlusionTexture")) return {};
    const std::size_t texture = material["occlusionTexture"]["index"].get<std::size_t>();
    const auto bytes = gltf::image_bytes(doc, doc.json["textures"][texture]["source"].get<std::size_t>());
    if (!bytes) return {};
    const auto image = image::decode_image({reinterpret_cast<const unsigned char*>(bytes->data()), bytes->size()}, "ao.png",
                                           color::Transfer::linear);
    return image ? image->pixels : std::vector<float>{};
  };
  ASSERT_EQ(given->json["materials"].size(), alone->json["materials"].size());
  for (std::size_t m = 0; m < alone->json["materials"].size(); ++m) {
    const auto& material = given->json["materials"][m];
    EXPECT_EQ(occlusion(*given, m), occlusion(*alone, m)) << material.dump();
    EXPECT_FALSE(occlusion(*alone, m).empty());
    if (material["name"] != "wood") {
      EXPECT_EQ(material["pbrMetallicRoughness"], alone->json["materials"][m]["pbrMetallicRoughness"]);
      continue;
    }
    EXPECT_EQ(material["pbrMetallicRoughness"]["metallicFactor"], 0.25);
    EXPECT_EQ(material["pbrMetallicRoughness"]["roughnessFactor"], 0.75);
    const std::vector<float> ao = occlusion(*given, m);
    EXPECT_LT(*std::min_element(ao.begin(), ao.end()), 0.9f) << "the bake occludes somewhere";
  }
  MATBAKE_VALIDATE_OR_SKIP(report, dir / "out/s.gltf");
  EXPECT_EQ(report->errors, 0) << report->summary;
}

// With per_instance, a manifest material given to a glTF material reaches every placement's copy
// of it (it reached the first placement's only), and each keeps its own baked AO.
TEST(CliBuildBake, AManifestMaterialReachesEveryPlacementsCopy) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  write_bytes(dir / "m.toml", "output = \"out\"\n[materials.wood]\nsources = { base_color = 0.5, metallic = 0.25, roughness = 0.75 }\n"
                              "[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"s.gltf\"\nbake = { from = \"showroom.gltf\", "
                              "maps = \"ao\", size = 16, per_instance = true, ao = { samples = 4 } }\n");
  const RunResult r = matbake({"--json", "build", (dir / "m.toml").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = gltf::read_document(dir / "out/s.gltf");
  ASSERT_TRUE(doc);
  std::vector<std::string> woods;
  std::set<int> occlusions;
  for (const auto& m : doc->json["materials"]) {
    const std::string name = m.value("name", "");
    if (name.rfind("wood", 0) != 0) continue;
    woods.push_back(name);
    EXPECT_EQ(m["pbrMetallicRoughness"]["metallicFactor"], 0.25) << name;
    EXPECT_EQ(m["pbrMetallicRoughness"]["roughnessFactor"], 0.75) << name;
    occlusions.insert(m["occlusionTexture"]["index"].get<int>());
  }
  EXPECT_EQ(woods, (std::vector<std::string>{"wood", "wood (pillar right)"}));
  EXPECT_EQ(occlusions.size(), 2u) << "each placement its own AO";
  const json report = json::parse(r.out);
  std::vector<std::string> copies;
  for (const auto& t : report["jobs"][1]["details"]["bake"]["textures"]) {
    if (t.contains("copy_of")) copies.push_back(t["copy_of"].get<std::string>() + " <- " + t["name"].get<std::string>());
  }
  EXPECT_NE(std::find(copies.begin(), copies.end(), "wood <- wood (pillar right)"), copies.end()) << report.dump();
}

// The kept maps of a scene that no longer bakes (renamed, its bake dropped) are removed by the next
// full build (they stayed for ever), and only they: another file in its folder, and a link there
// with what it points to, are left.
TEST(CliBuildBake, TheKeptMapsOfASceneThatNoLongerBakesAreRemoved) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  const fs::path bakes = dir / "out/.matbake/bake";
  const auto run = [&](const std::string& manifest) {
    write_bytes(dir / "m.toml", manifest);
    const RunResult r = matbake({"build", (dir / "m.toml").string()});
    EXPECT_EQ(r.exit_code, 0) << r.err;
  };
  const std::string as_s = manifest_text("out", "[\"height\"]", 4);
  std::string as_t = as_s;
  as_t.replace(as_t.find("[scenes.s]"), 10, "[scenes.t]");
  run(as_s);
  ASSERT_TRUE(fs::exists(bakes / "scene-s/kept/maps.json"));
  write_bytes(bakes / "scene-s/notes.txt", "mine");
  fs::create_directories(dir / "elsewhere");
  for (const char* f : {"maps.json", "0_height.f32", "s.glb"}) write_bytes(dir / "elsewhere" / f, "not matbake's");
  fs::create_directory_symlink(dir / "elsewhere", bakes / "scene-x");
  run(as_t);
  EXPECT_TRUE(fs::exists(bakes / "scene-t/kept/maps.json"));
  EXPECT_FALSE(fs::exists(bakes / "scene-s/kept"));
  EXPECT_EQ(read_bytes(bakes / "scene-s/notes.txt"), "mine");
  EXPECT_EQ(fs::directory_iterator(bakes / "scene-s")->path().filename(), "notes.txt");
  EXPECT_TRUE(fs::is_symlink(bakes / "scene-x"));
  for (const char* f : {"maps.json", "0_height.f32", "s.glb"}) EXPECT_EQ(read_bytes(dir / "elsewhere" / f), "not matbake's") << f;
  // The bake dropped: its folder goes; the scene is exported as it is.
  const std::string unbaked = as_t.substr(0, as_t.find("bake = "));
  run(unbaked);
  EXPECT_FALSE(fs::exists(bakes / "scene-t"));
  EXPECT_TRUE(fs::exists(dir / "out/s.glb"));
  // OUT/.matbake/bake itself a link (no scene bakes, so the plan does not look): not followed.
  fs::remove_all(bakes);
  fs::create_directories(dir / "elsewhere/scene-q/kept");
  write_bytes(dir / "elsewhere/scene-q/kept/maps.json", "not matbake's");
  fs::create_directory_symlink(dir / "elsewhere", bakes);
  write_bytes(dir / "showroom.gltf", read_bytes(dir / "showroom.gltf") + " ");  // a build that runs
  run(unbaked);
  EXPECT_EQ(read_bytes(dir / "elsewhere/scene-q/kept/maps.json"), "not matbake's");
}

// The bake's work folder (OUT/.matbake/bake/scene-NAME, its kept maps) is written to and emptied by
// the build: a link planted there to another folder, at any depth, is refused before any job runs,
// and the folder it points to is left as it was (it held the bake's files and lost them before).
TEST(CliBuildBake, ALinkPlantedInTheBakesWorkFolderIsRefused) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  build(dir.path(), "out", "[\"height\"]", 4);
  const fs::path work = dir / "out/.matbake/bake/scene-s";
  ASSERT_TRUE(fs::exists(work / "kept/maps.json"));
  for (const fs::path& planted : {work / "kept", work, work.parent_path()}) {
    fs::remove_all(planted);
    fs::create_directories(dir / "elsewhere");
    write_bytes(dir / "elsewhere/mine.txt", "not matbake's");
    fs::create_directory_symlink(dir / "elsewhere", planted);
    write_bytes(dir / "m.toml", manifest_text("out", "[\"height\"]", 8));
    const RunResult r = matbake({"build", (dir / "m.toml").string()});
    EXPECT_EQ(r.exit_code, 1) << planted;
    expect_one_error_line(r, planted.string(), "is a link out of the output folder");
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(dir / "elsewhere")) left.push_back(e.path().filename().string());
    EXPECT_EQ(left, std::vector<std::string>{"mine.txt"}) << planted;
    fs::remove(planted);
    fs::remove_all(dir / "elsewhere");
  }
}

// A map the bake writes beside the scene (here OUT/materials/s_wood_height.exr: scene output
// materials/s.glb, material wood) named as another job's output (material s_wood's texture
// "height" in EXR): the scene job fails naming the file before it exports anything, and the other
// job's output is its own, in whichever order they ran.
TEST(CliBuildBake, ABakedMapNamedAsAnotherJobsOutputFailsTheSceneJob) {
  TempDir dir;
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  write_bytes(dir / "height.json", "{\"name\": \"height\", \"textures\": [{\"name\": \"height\", \"channels\": [{\"source\": \"roughness\"}]}]}");
  write_bytes(dir / "m.toml", "output = \"out\"\n[materials.s_wood]\nsources = { base_color = 0.5, metallic = 0, roughness = 0.25 }\nsize = \"4x4\"\n"
                              "layout = \"height.json\"\nformat = \"exr\"\nbits = \"float\"\nvalidate = { enabled = false }\n"
                              "[scenes.s]\ninput = \"showroom.gltf\"\noutput = \"materials/s.glb\"\n"
                              "bake = { from = \"showroom.gltf\", maps = \"height\", size = 16 }\n");
  const RunResult r = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const fs::path clash = dir / "out/materials/s_wood_height.exr";
  EXPECT_NE(r.err.find(clash.string() + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("another output of this build"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/materials/s.glb"));
  const auto texture = image::read_image(clash, color::Transfer::linear);
  ASSERT_TRUE(texture) << texture.error().to_string();
  EXPECT_EQ(texture->width, 4);
  EXPECT_EQ(texture->pixels.front(), 0.25f);
}

}  // namespace
}  // namespace matbake::test
