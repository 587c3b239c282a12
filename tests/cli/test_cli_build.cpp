// `matbake build` and `matbake plan` end to end: the bundled example (validator-clean, each source
// decoded once, a second run does nothing), texel values of packed outputs, byte-identical outputs
// across job counts, what makes a job out of date, failing jobs beside finished ones, validation
// rules, depfiles, JSON, dry runs, Ninja, and interrupts that leave no temporary file.
#include <gtest/gtest.h>

#include <regex>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <algorithm>
#include <map>
#include <sstream>
#include <thread>

#include "lib/src/gltf/document.hpp"
#include "matbake/cluster.hpp"
#include "matbake/params.hpp"
#include "matbake/preview.hpp"
#include "support/files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/sbatch.hpp"
#include "support/temp_dir.hpp"

extern char** environ;

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;


json run_json(const std::vector<std::string>& args, int expected_exit = 0) {
  std::vector<std::string> all = {"--json"};
  all.insert(all.end(), args.begin(), args.end());
  const RunResult r = matbake(all);
  EXPECT_EQ(r.exit_code, expected_exit) << r.err;
  return json::parse(r.out, nullptr, false);
}

// Every file under `folder` but the stamps, by relative path, with its bytes.
std::map<std::string, std::string> outputs_under(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    const std::string rel = fs::relative(e.path(), folder).string();
    if (e.is_regular_file() && rel.rfind(".matbake", 0) != 0) files[rel] = read_bytes(e.path());
  }
  return files;
}

std::vector<std::string> temporary_files_under(const fs::path& folder) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    if (e.path().filename().string().find(".matbake-") != std::string::npos) found.push_back(e.path().string());
  }
  return found;
}

std::string outcome_of(const json& report, const std::string& job) {
  for (const json& j : report["jobs"]) {
    if (j["name"] == job) return j["outcome"].get<std::string>() + (j.contains("reason") ? ": " + j["reason"].get<std::string>() : "");
  }
  return "absent";
}

TEST(CliBuild, ExampleBuildsOnceAndPassesTheValidator) {
  TempDir dir;
  copy_example(dir.path());
  const json first = run_json({"build", (dir / "showroom.toml").string()});
  ASSERT_TRUE(first.is_object());
  EXPECT_EQ(first["built"], 6);
  EXPECT_EQ(first["failed"], 0);
  // Six source files, read by five material jobs and the scene job: each decoded once.
  EXPECT_EQ(first["images_decoded"], 6);
  // The scene job reads the scene, its buffer, and every material's sources.
  for (const json& j : first["jobs"]) {
    if (j["name"] != "scene:showroom") continue;
    EXPECT_EQ(j["inputs"].size(), 8u) << j["inputs"].dump();
    EXPECT_EQ(j["details"]["materials"].size(), 5u);
    EXPECT_GT(j["details"]["ao_rays"].get<double>(), 0);
  }

  // Rubber is metal-rough with an sRGB base colour: the packed base colour keeps its codes, alpha
  // 255 (no mask); ORM = (1, 0.85, 0) → (255, 217, 0).
  const RawImage source = read_raw(dir / "textures/rubber_albedo.png");
  const RawImage base = read_raw(dir / "out/materials/rubber_base_color.png");
  ASSERT_EQ(base.channels, 4);
  ASSERT_EQ(base.width, source.width);
  for (std::size_t i = 0; i < std::size_t(source.width * source.height); i += 997) {
    ASSERT_EQ(base.samples[4 * i], source.samples[i]);
    ASSERT_EQ(base.samples[4 * i + 1], source.samples[i]);
    ASSERT_EQ(base.samples[4 * i + 3], 255);
  }
  const RawImage orm = read_raw(dir / "out/materials/rubber_orm.png");
  EXPECT_EQ(orm.samples[0], 255);
  EXPECT_EQ(orm.samples[1], 217);
  EXPECT_EQ(orm.samples[2], 0);
  // Gold is checked against the table's gold and passes.
  const json gold = json::parse(read_bytes(dir / "out/materials/gold_trim.validation.json"));
  EXPECT_EQ(gold["material"]["name"], "gold");
  EXPECT_EQ(gold["passed"], true);
  EXPECT_EQ(gold["classes"]["metal"], 256 * 256);

  // The scene's AO is baked into the ORM textures (red), one material copy per placement: 10
  // placements of 5 materials; each material's occlusion is its metallic-roughness texture.
  {
    const auto doc = gltf::read_document(dir / "out/showroom.glb");
    ASSERT_TRUE(doc) << doc.error().to_string();
    ASSERT_EQ(doc->json["materials"].size(), 10u);
    for (const auto& m : doc->json["materials"]) {
      EXPECT_EQ(m["occlusionTexture"]["index"], m["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"]) << m.dump();
    }
  }
  MATBAKE_VALIDATE_OR_SKIP(report, dir / "out/showroom.glb");
  EXPECT_EQ(report->errors, 0) << report->summary;
  EXPECT_EQ(report->warnings, 0) << report->summary;

  const RunResult second = matbake({"build", (dir / "showroom.toml").string()});
  EXPECT_EQ(second.exit_code, 0) << second.err;
  EXPECT_EQ(second.out, "nothing to do: 6 jobs up to date\n");
  EXPECT_EQ(second.err, "");
}

// A stamp holds what its job reads: a validation setting is the material jobs' alone, so changing it
// rebuilds them and not the scene (whose bytes and stamp stay as they were), and the reason names it.
TEST(CliBuild, AValidationSettingRebuildsTheMaterialsOnly) {
  TempDir dir;
  copy_example(dir.path(), true);
  const std::string manifest = (dir / "showroom.toml").string();
  std::string text = read_bytes(dir / "showroom.toml");
  text.insert(text.find("tolerance = 0.1"), "worst = 5\n");
  write_bytes(dir / "showroom.toml", text);
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);
  const std::string scene = read_bytes(dir / "out/showroom.glb"), stamp = read_bytes(dir / "out/.matbake/scene-showroom.json");

  text.replace(text.find("worst = 5"), 9, "worst = 6");
  write_bytes(dir / "showroom.toml", text);
  const json dry = run_json({"build", manifest, "-n"});
  EXPECT_EQ(dry["out_of_date"], 5) << dry.dump();
  EXPECT_EQ(outcome_of(dry, "scene:showroom"), "up_to_date");
  for (const json& job : dry["jobs"]) {
    if (job["name"] == "scene:showroom") continue;
    EXPECT_EQ(job["reason"], "its options changed: validate.worst 5 → 6");
    EXPECT_EQ(job["changed"], json::parse(R"([{"parameter": "validate.worst", "old": 5, "new": 6}])")) << job.dump();
  }
  const RunResult told = matbake({"build", manifest, "-n"});
  EXPECT_NE(told.out.find("would build material:wood: its options changed: validate.worst 5 → 6"), std::string::npos) << told.out;

  const json built = run_json({"build", manifest});
  EXPECT_EQ(built["built"], 5);
  EXPECT_EQ(outcome_of(built, "scene:showroom"), "up_to_date");
  EXPECT_EQ(read_bytes(dir / "out/showroom.glb"), scene);
  EXPECT_EQ(read_bytes(dir / "out/.matbake/scene-showroom.json"), stamp);
}

// A job whose last run did not write an output it now has (its stamp from a matbake that wrote no
// ball) is out of date, saying so, and the build writes it: it was up to date without it.
TEST(CliBuild, AnOutputTheLastRunDidNotWriteRebuildsItsJob) {
  TempDir dir;
  copy_example(dir.path(), true);
  const std::string manifest = (dir / "showroom.toml").string();
  ASSERT_EQ(matbake({"build", manifest, "--quiet"}).exit_code, 0);
  const fs::path stamp_file = dir / "out/.matbake/material-wood.json", ball = dir / "out/materials/wood_preview.png";
  json stamp = json::parse(read_bytes(stamp_file));
  json kept = json::array();
  for (const json& f : stamp["outputs"]) {
    if (!f["path"].get<std::string>().ends_with("_preview.png")) kept.push_back(f);
  }
  ASSERT_EQ(kept.size() + 1, stamp["outputs"].size());
  stamp["outputs"] = kept;
  write_bytes(stamp_file, stamp.dump(1) + "\n");
  fs::remove(ball);
  const json dry = run_json({"build", manifest, "-n"});
  for (const json& job : dry["jobs"]) {
    EXPECT_EQ(job["outcome"], job["name"] == "material:wood" ? "out_of_date" : "up_to_date") << job.dump();
    if (job["name"] == "material:wood") {
      EXPECT_EQ(job["reason"], "new output: " + ball.string());
    }
  }
  ASSERT_EQ(matbake({"build", manifest, "--quiet"}).exit_code, 0);
  EXPECT_TRUE(fs::exists(ball));
}

TEST(CliBuild, SameBytesWhateverTheJobCount) {
  TempDir dir;
  copy_example(dir.path(), true);
  ASSERT_EQ(matbake({"build", (dir / "showroom.toml").string(), "--jobs", "1"}).exit_code, 0);
  const auto one = outputs_under(dir / "out");
  EXPECT_EQ(one.size(), 21u);  // 5 × (2 textures + report + ball) + the .glb
  const RunResult again = matbake({"build", (dir / "showroom.toml").string(), "--jobs", "2", "--force"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(outputs_under(dir / "out"), one);
}

TEST(CliBuild, RebuildsWhatChangedAndOnlyThat) {
  TempDir dir;
  copy_example(dir.path(), true);
  const std::string manifest = (dir / "showroom.toml").string();
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);

  // A touched file whose bytes are the same is not a change.
  const fs::path wood = dir / "textures/wood_albedo.png";
  fs::last_write_time(wood, fs::last_write_time(wood) + std::chrono::seconds(5));
  json dry = run_json({"build", manifest, "--dry-run"});
  EXPECT_EQ(dry["out_of_date"], 0) << dry.dump();
  // A real run then records the new time, so the next one need not hash the file again.
  EXPECT_EQ(run_json({"build", manifest})["up_to_date"], 6);
  const json stamp = json::parse(read_bytes(dir / "out/.matbake/material-wood.json"));
  EXPECT_EQ(stamp["inputs"][0]["path"], "textures/wood_albedo.png");  // relative to the manifest's folder
  EXPECT_EQ(stamp["inputs"][0]["mtime"].get<std::int64_t>(),
            std::chrono::duration_cast<std::chrono::nanoseconds>(
                std::chrono::file_clock::to_sys(fs::last_write_time(wood)).time_since_epoch())
                .count());  // nanoseconds since 1970, as stat gives them

  // New bytes in the rubber texture: rubber and the scene (which uses it), nothing else.
  write_raw(dir / "textures/rubber_albedo.png", 2, 2, 1, "uint8", {50, 51, 52, 53});
  dry = run_json({"build", manifest, "--dry-run"});
  EXPECT_EQ(dry["out_of_date"], 2);
  EXPECT_EQ(outcome_of(dry, "material:rubber"), "out_of_date: input changed: " + (dir / "textures/rubber_albedo.png").string());
  EXPECT_EQ(outcome_of(dry, "scene:showroom").rfind("out_of_date: input changed", 0), 0u);
  EXPECT_EQ(outcome_of(dry, "material:wood"), "up_to_date");
  const RunResult dry_text = matbake({"build", manifest, "-n"});
  EXPECT_NE(dry_text.out.find("would build material:rubber: input changed"), std::string::npos) << dry_text.out;
  EXPECT_NE(dry_text.out.find("2 of 6 jobs would be built"), std::string::npos);
  json built = run_json({"build", manifest});
  EXPECT_EQ(built["built"], 2);
  EXPECT_EQ(read_raw(dir / "out/materials/rubber_base_color.png").width, 2);

  // An option: only the material it belongs to, and the scene that uses it.
  std::string text = read_bytes(dir / "showroom.toml");
  text.replace(text.find("gloss = 0.45"), 12, "gloss = 0.50");
  write_bytes(dir / "showroom.toml", text);
  dry = run_json({"build", manifest, "--dry-run"});
  EXPECT_EQ(outcome_of(dry, "material:wood"), "out_of_date: its options changed: sources.gloss [0.45] → [0.5]");
  EXPECT_EQ(outcome_of(dry, "scene:showroom"),
            "out_of_date: its options changed: materials.wood.sources.gloss [0.45] → [0.5]");
  EXPECT_EQ(dry["out_of_date"], 2);
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);

  // A stamp of an older form (no "form": matbake before the parameter descriptions) rebuilds once, saying so.
  json old_stamp = json::parse(read_bytes(dir / "out/.matbake/material-rubber.json"));
  old_stamp.erase("form");
  write_bytes(dir / "out/.matbake/material-rubber.json", old_stamp.dump());
  dry = run_json({"build", manifest, "--dry-run"});
  EXPECT_EQ(outcome_of(dry, "material:rubber"), "out_of_date: its stamp is from an older matbake (recorded anew)");
  EXPECT_EQ(dry["out_of_date"], 1);
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);
  EXPECT_EQ(run_json({"build", manifest, "--dry-run"})["out_of_date"], 0);

  // A deleted or edited output is built again.
  fs::remove(dir / "out/materials/glass_orm.png");
  write_bytes(dir / "out/materials/painted_metal.validation.json", "{}");
  dry = run_json({"build", manifest, "--dry-run"});
  EXPECT_EQ(outcome_of(dry, "material:glass"), "out_of_date: output missing: " + (dir / "out/materials/glass_orm.png").string());
  EXPECT_EQ(outcome_of(dry, "material:painted_metal").rfind("out_of_date: output changed since it was built", 0), 0u);
  built = run_json({"build", manifest, "--only", "material:glass"});
  EXPECT_EQ(built["jobs"].size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "out/materials/glass_orm.png"));

  // --force builds all; an unknown --only is a usage error.
  EXPECT_EQ(run_json({"build", manifest, "--force"})["built"], 6);
  const RunResult unknown = matbake({"build", manifest, "--only", "texture:rubber"});
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.err.find("no job 'texture:rubber' (jobs: material:glass, "), std::string::npos) << unknown.err;
  const RunResult misspelt = matbake({"build", manifest, "--only", "material:rubbr"});
  EXPECT_EQ(misspelt.exit_code, 2);
  EXPECT_NE(misspelt.err.find("no job 'material:rubbr'; did you mean material:rubber?"), std::string::npos) << misspelt.err;
}

TEST(CliBuild, AMovedOrCopiedTreeIsUpToDate) {
  TempDir dir;
  fs::create_directories(dir / "a");
  copy_example(dir / "a", true);
  ASSERT_EQ(matbake({"build", (dir / "a/showroom.toml").string()}).exit_code, 0);
  // Moved (times kept): nothing to do. Stamps hold paths relative to the manifest's and output folders.
  fs::rename(dir / "a", dir / "b");
  EXPECT_EQ(run_json({"build", (dir / "b/showroom.toml").string(), "--dry-run"})["out_of_date"], 0);
  // Copied (new times, same bytes): the hashes decide, so nothing is built either.
  fs::copy(dir / "b", dir / "c", fs::copy_options::recursive);
  const json copied = run_json({"build", (dir / "c/showroom.toml").string()});
  EXPECT_EQ(copied["built"], 0) << copied.dump();
  EXPECT_EQ(copied["up_to_date"], 6);
  // The same sources built from scratch elsewhere give the same bytes.
  fs::create_directories(dir / "d");
  copy_example(dir / "d", true);
  ASSERT_EQ(matbake({"build", (dir / "d/showroom.toml").string(), "--jobs", "1"}).exit_code, 0);
  EXPECT_EQ(outputs_under(dir / "d/out"), outputs_under(dir / "b/out"));
}

TEST(CliBuild, StaleOutputsAreRemovedAndOnlyThose) {
  TempDir dir;
  copy_example(dir.path(), true);
  const std::string manifest = (dir / "showroom.toml").string();
  ASSERT_EQ(matbake({"build", manifest}).exit_code, 0);
  write_bytes(dir / "out/notes.txt", "mine");
  write_bytes(dir / "out/materials/mine_orm.png", "mine too");
  const auto edit = [&](const std::string& from, const std::string& to) {
    std::string text = read_bytes(dir / "showroom.toml");
    const std::size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    write_bytes(dir / "showroom.toml", text);
  };
  // Rubber moves to Unity HDRP's layout: its glTF ORM texture is stale. Kept when asked, and
  // listed by a dry run, then removed by the next full run.
  edit("metallic = 0.0, roughness = 0.85 }\nlayout = \"gltf-orm\"", "metallic = 0.0, roughness = 0.85 }\nlayout = \"unity-hdrp\"");
  const fs::path rubber_orm = dir / "out/materials/rubber_orm.png";
  ASSERT_TRUE(fs::exists(rubber_orm));
  json kept = run_json({"build", manifest, "--keep-stale"});
  EXPECT_EQ(kept["stale"]["kept"], json::array({rubber_orm.string()})) << kept["stale"].dump();
  EXPECT_TRUE(fs::exists(rubber_orm));
  const RunResult dry = matbake({"build", manifest, "-n"});
  EXPECT_NE(dry.out.find("would remove " + rubber_orm.string() + ": no job makes it now"), std::string::npos) << dry.out;
  const RunResult removed = matbake({"build", manifest});
  EXPECT_NE(removed.out.find("removed " + rubber_orm.string() + ": no job makes it now"), std::string::npos) << removed.out;
  EXPECT_FALSE(fs::exists(rubber_orm));

  // Wood's validation turned off: its report goes. Gold trim removed from the manifest: its
  // texture, report and stamp go; its texture changed by someone first stays (and is forgotten).
  edit("decode = \"srgb\"", "decode = \"srgb\"\nvalidate = { enabled = false }");
  edit("[materials.gold_trim]", "[materials.old_gold_trim]");
  write_bytes(dir / "out/materials/gold_trim_orm.png", "changed by hand");
  // The scene was built with the manifest's gold_trim: losing it is refused unless pruned.
  const RunResult refused = matbake({"build", manifest});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("scenes.showroom: its glTF material 'gold_trim' was built with a manifest material"), std::string::npos)
      << refused.err;
  EXPECT_TRUE(fs::exists(dir / "out/materials/gold_trim_base_color.png"));
  const json cleaned = run_json({"build", manifest, "--prune"});
  std::vector<std::string> gone = cleaned["stale"]["removed"];
  std::sort(gone.begin(), gone.end());
  EXPECT_EQ(gone, (std::vector<std::string>{(dir / "out/materials/gold_trim.validation.json").string(),
                                            (dir / "out/materials/gold_trim_base_color.png").string(),
                                            (dir / "out/materials/gold_trim_preview.png").string(),
                                            (dir / "out/materials/wood.validation.json").string()}));
  EXPECT_EQ(cleaned["stale"]["changed"], json::array({(dir / "out/materials/gold_trim_orm.png").string()}));
  EXPECT_EQ(read_bytes(dir / "out/materials/gold_trim_orm.png"), "changed by hand");
  EXPECT_FALSE(fs::exists(dir / "out/.matbake/material-gold_trim.json"));
  EXPECT_TRUE(fs::exists(dir / "out/materials/old_gold_trim_orm.png"));
  EXPECT_EQ(read_bytes(dir / "out/notes.txt"), "mine");
  EXPECT_EQ(read_bytes(dir / "out/materials/mine_orm.png"), "mine too");
  EXPECT_EQ(run_json({"build", manifest})["stale"]["removed"], json::array());
}

TEST(CliBuild, FailingJobsAreReportedAndTheOthersFinish) {
  TempDir dir;
  write_bytes(dir / "corrupt.png", "\x89PNG\r\n\x1a\nnot really");
  write_bytes(dir / "m.toml", R"(
[validate]
gate = true
[materials.good]
sources = { kd = [0.5, 0.4, 0.3], ks = 0.04, gloss = 0.7 }
layout = "gltf-orm"
[materials.missing]
sources = { kd = "missing.png", ks = 0.04, gloss = 0.5 }
layout = "gltf-orm"
[materials.corrupt]
sources = { kd = "corrupt.png", ks = 0.04, gloss = 0.5 }
layout = "gltf-orm"
[materials.below_real]
sources = { kd = 0.5, ks = 0.01, gloss = 0.5 }
layout = "gltf-orm"
)");
  const RunResult r = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(r.exit_code, 1);
  // One line per failed job naming the file and the job, then the summary; the progress lines of
  // a log (stderr is not a terminal): each job's start, the finished job's end; no library noise.
  std::vector<std::string> lines;
  for (std::size_t at = 0; at < r.err.size();) {
    const std::size_t end = r.err.find('\n', at);
    const std::string line = r.err.substr(at, end - at);
    if (line.rfind("[", 0) == 0) {
      EXPECT_NE(line.find("/4] material:good built ("), std::string::npos) << line;
    } else if (line.find(" started (") != std::string::npos) {
      EXPECT_TRUE(std::regex_match(line, std::regex("material:[a-z_]+ started \\([1-4] of 4\\)"))) << line;
    } else {
      lines.push_back(line);
    }
    at = end + 1;
  }
  ASSERT_EQ(lines.size(), 4u) << r.err;
  std::sort(lines.begin(), lines.begin() + 3);
  // Each names the manifest's line and column of the value at fault, then the file.
  const std::string manifest = (dir / "m.toml").string();
  // Sorted as text: corrupt (line 11), below_real (13), missing (8).
  EXPECT_EQ(lines[1], "matbake: error: " + manifest + ":13:1: materials.below_real: validation: 1 of 1 texels flagged "
                      "(100%; max_violations 0%); the texels are in " +
                      (dir / "out/materials/below_real.validation.json").string() + " (material:below_real)");
  EXPECT_EQ(lines[2], "matbake: error: " + manifest + ":8:18: materials.missing.sources.kd: " + (dir / "missing.png").string() +
                          ": no such file (material:missing)");
  EXPECT_EQ(lines[0].rfind("matbake: error: " + manifest + ":11:18: materials.corrupt: " + (dir / "corrupt.png").string() + ": ", 0),
            0u)
      << lines[0];
  EXPECT_NE(lines[0].find("(material:corrupt)"), std::string::npos);
  EXPECT_EQ(lines[3], "matbake: error: " + (dir / "m.toml").string() + ": 3 of 4 jobs failed");
  // The good material is complete (a 1×1 texture of constants); the failed ones left no partial file,
  // and the one over its validation gate only its report (no textures).
  const RawImage good = read_raw(dir / "out/materials/good_base_color.png");
  EXPECT_EQ(good.width, 1);
  EXPECT_EQ(list_folder(dir / "out/materials"),
            (std::vector<std::string>{"below_real.validation.json", "good.validation.json", "good_base_color.png", "good_orm.png",
                                      "good_preview.png"}));
  // Failed jobs run again next time; the finished one does not.
  const json dry = run_json({"build", (dir / "m.toml").string(), "-n"}, 1);  // exit 1: a job would fail
  EXPECT_EQ(outcome_of(dry, "material:good"), "up_to_date");
  // A source that is not there fails in a dry run too, saying so, rather than "would build".
  EXPECT_EQ(outcome_of(dry, "material:missing"), "failed: no earlier build");
  EXPECT_EQ(outcome_of(dry, "material:below_real"), "out_of_date: no earlier build");

  // A rule that allows the flagged texels turns the failure into a warning.
  std::string text = read_bytes(dir / "m.toml");
  text += "validate = { max_violations = 1.0 }\n";
  write_bytes(dir / "m.toml", text);
  const RunResult allowed = matbake({"build", (dir / "m.toml").string(), "--only", "material:below_real"});
  EXPECT_EQ(allowed.exit_code, 0) << allowed.err;
  EXPECT_NE(allowed.err.find("matbake: warning: material:below_real: validation: 1 of 1 texels flagged"), std::string::npos)
      << allowed.err;
}

// A scene that fails while it is exported (its buffer is not there) names the manifest's line of
// its input, then the file at fault.
// A material over its validation gate fails and writes no textures; the scene using it is skipped,
// as Make and Ninja skip what depends on a failed target. With the gate off it is advisory.
TEST(CliBuild, AFailedMaterialSkipsItsScenesAndValidationCanBeAdvisory) {
  TempDir dir;
  copy_example(dir.path(), true);
  const std::string manifest = (dir / "showroom.toml").string();
  std::string text = read_bytes(dir / "showroom.toml");
  text.replace(text.find("reference = \"gold\""), 18, "reference = \"silver\"");
  write_bytes(dir / "showroom.toml", text);
  const RunResult gated = matbake({"build", manifest});
  EXPECT_EQ(gated.exit_code, 1);
  EXPECT_NE(gated.err.find("scene:showroom skipped: material:gold_trim failed"), std::string::npos) << gated.err;
  EXPECT_NE(gated.out.find("failed 1, skipped 1; 1 failed validation;"), std::string::npos) << gated.out;
  EXPECT_EQ(gated.out.find("advisory"), std::string::npos) << gated.out;
  const json report = run_json({"build", manifest}, 1);
  EXPECT_EQ(outcome_of(report, "scene:showroom"), "skipped: material:gold_trim failed");
  EXPECT_EQ(report["skipped"], 1);
  EXPECT_FALSE(fs::exists(dir / "out/showroom.glb"));
  EXPECT_FALSE(fs::exists(dir / "out/materials/gold_trim_orm.png"));
  EXPECT_TRUE(fs::exists(dir / "out/materials/gold_trim.validation.json"));

  text.replace(text.find("gate = true"), 11, "gate = false");
  write_bytes(dir / "showroom.toml", text);
  const RunResult advisory = matbake({"build", manifest});
  EXPECT_EQ(advisory.exit_code, 0) << advisory.err;
  EXPECT_NE(advisory.err.find("material:gold_trim: validation: "), std::string::npos) << advisory.err;
  EXPECT_NE(advisory.err.find("over the limit (advisory: validate.gate is off)"), std::string::npos) << advisory.err;
  EXPECT_NE(advisory.out.find("; 1 over their validation limit (advisory: validate.gate is off)"), std::string::npos) << advisory.out;
  EXPECT_TRUE(fs::exists(dir / "out/showroom.glb"));
  EXPECT_EQ(run_json({"build", manifest, "--force"})["over_validation_limit"], 1);
}

TEST(CliBuild, AFailingSceneNamesItsInputsLine) {
  TempDir dir;
  write_bytes(dir / "s.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "gone.bin", "byteLength": 12}]})");
  write_bytes(dir / "m.toml", "[scenes.s]\ninput = \"s.gltf\"\n");
  const RunResult r = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(r.exit_code, 1);
  ASSERT_EQ(r.err.rfind("scene:s started (1 of 1)\n", 0), 0u) << r.err;  // the log's progress line, then the error
  const std::size_t error_line = r.err.find('\n') + 1;
  const std::string first = r.err.substr(error_line, r.err.find('\n', error_line) - error_line);
  EXPECT_EQ(first.rfind("matbake: error: " + (dir / "m.toml").string() + ":2:9: scenes.s: ", 0), 0u) << r.err;
  EXPECT_NE(first.find("gone.bin"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out/s.glb"));
}

// A layout file is named with or without its ".json", relative to the manifest whatever the current
// folder, and is an input of exactly the jobs that use it. References that do not resolve are errors
// at their line and column, in a dry run and a real one alike: no material silently left out.
TEST(CliBuild, LayoutAndMaterialReferencesResolveFromTheManifest) {
  TempDir dir;
  fs::create_directories(dir / "project/layouts");
  std::string layout = read_bytes(fs::path(MATBAKE_SOURCE_DIR) / "presets/layouts/gltf-orm.json");
  write_bytes(dir / "project/layouts/mine.json", layout);
  const std::string constants = "sources = { kd = 0.5, ks = 0.04, gloss = 0.5 }\nvalidate = { enabled = false }\n";
  const auto manifest_with = [&](const std::string& a_layout, const std::string& extra) {
    write_bytes(dir / "project/m.toml", "[materials.a]\n" + constants + "layout = \"" + a_layout + "\"\n" +
                                            "[materials.b]\n" + constants + "layout = \"layouts/mine.json\"\n" +
                                            "[materials.c]\n" + constants + "layout = \"gltf-orm\"\n" + extra);
  };
  manifest_with("layouts/mine", "");
  const std::string manifest = (dir / "project/m.toml").string();
  const json first = run_json({"build", manifest});
  EXPECT_EQ(first["built"], 3) << first.dump();
  for (const char* job : {"material:a", "material:b"}) {
    bool has_layout = false;
    for (const json& j : first["jobs"]) {
      if (j["name"] == job) has_layout = j["inputs"] == json::array({(dir / "project/layouts/mine.json").string()});
    }
    EXPECT_TRUE(has_layout) << job << " " << first.dump();
  }
  EXPECT_EQ(read_bytes(dir / "project/out/materials/a_orm.png"), read_bytes(dir / "project/out/materials/c_orm.png"));

  // Editing the layout file rebuilds the two materials that use it, not the preset's.
  const std::string occlusion = "{\"source\": \"occlusion\", \"default\": 1}";
  layout.replace(layout.find(occlusion), occlusion.size(), "{\"source\": \"occlusion\", \"default\": 0.5}");
  write_bytes(dir / "project/layouts/mine.json", layout);
  const json dry = run_json({"build", manifest, "-n"});
  EXPECT_EQ(outcome_of(dry, "material:a"), "out_of_date: input changed: " + (dir / "project/layouts/mine.json").string());
  EXPECT_EQ(outcome_of(dry, "material:b"), "out_of_date: input changed: " + (dir / "project/layouts/mine.json").string());
  EXPECT_EQ(outcome_of(dry, "material:c"), "up_to_date");
  EXPECT_EQ(run_json({"build", manifest})["built"], 2);
  EXPECT_EQ(read_raw(dir / "project/out/materials/a_orm.png").samples[0], 128);  // occlusion 0.5 now
  EXPECT_EQ(read_raw(dir / "project/out/materials/c_orm.png").samples[0], 255);

  // Typos: one error line at the value's line and column, from -n and from a real run, nothing written.
  const std::string at = manifest + ":4:10: materials.a.layout: layout ";
  const std::pair<std::string, std::string> typos[] = {
      {"gltf-ormm", at + "'gltf-ormm': no preset of that name (presets: gltf-metal-rough, gltf-orm, gltf-pbr, schuler, unity-hdrp, "
                         "unity-urp, unreal-orm; did you mean gltf-orm?) and no layout file " +
                         (dir / "project/gltf-ormm.json").string()},
      {"layouts/typo.json", at + "'layouts/typo.json': no preset of that name (presets: gltf-metal-rough, gltf-orm, gltf-pbr, "
                                 "schuler, unity-hdrp, unity-urp, unreal-orm) and no layout file " +
                                 (dir / "project/layouts/typo.json").string()},
  };
  for (const auto& [typo, says] : typos) {
    manifest_with(typo, "");
    for (const char* dry_run : {"-n", "--force"}) {
      const RunResult r = matbake({"build", manifest, dry_run});
      EXPECT_EQ(r.exit_code, 1) << r.err;
      EXPECT_EQ(r.err, "matbake: error: " + says + "\n");
    }
  }
  manifest_with("layouts/mine", "[materials.d]\nsources = { kd = 0.5, ks = 0.04, gloss = 0.5 }\nreference = \"gould\"\n");
  for (const char* dry_run : {"-n", "--force"}) {
    const RunResult r = matbake({"build", manifest, dry_run});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("matbake: error: " + manifest + ":15:13: materials.d.reference: unknown material 'gould'; near: gold"
                         " (material:d)\n"),
              std::string::npos)
        << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "project/out/materials/d.validation.json"));
}

TEST(CliBuild, BadManifestsAreOneLineAndWriteNothing) {
  TempDir dir;
  write_bytes(dir / "typo.toml", "[materials.a]\nsources = { kd = 0.5 }\nlayuot = \"gltf-orm\"\n");
  write_bytes(dir / "escape.toml", "[scenes.s]\ninput = \"s.gltf\"\noutput = \"../../s.glb\"\n");
  write_bytes(dir / "overwrite.toml", "output = \".\"\n[materials.a]\nsources = { kd = \"materials/a_a.png\" }\nlayout = \"schuler\"\n");
  const std::pair<const char*, std::string> cases[] = {
      {"typo.toml", (dir / "typo.toml").string() + ":3:1: unknown key 'layuot' in materials.a"},
      {"escape.toml", (dir / "escape.toml").string() + ":3:10: scenes.s.output '../../s.glb': a .gltf or .glb path inside"},
      {"missing.toml", (dir / "missing.toml").string() + ": cannot read the manifest"},
      {"overwrite.toml", (dir / "materials/a_a.png").string() + ": material:a would overwrite an input"},
  };
  for (const auto& [file, says] : cases) {
    const RunResult r = matbake({"build", (dir / file).string()});
    EXPECT_EQ(r.exit_code, 1) << file;
    EXPECT_EQ(r.err.rfind("matbake: error: " + says, 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_EQ(list_folder(dir.path()), (std::vector<std::string>{"escape.toml", "overwrite.toml", "typo.toml"}));
}

TEST(CliBuild, DepfileStampAndJson) {
  TempDir dir;
  fs::create_directories(dir / "my assets");
  const fs::path folder = dir / "my assets";
  write_raw(folder / "k d.png", 2, 2, 3, "uint8", {100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210});
  write_bytes(folder / "m.toml", "[materials.brick]\nsources = { kd = \"k d.png\", ks = 0.04, gloss = 0.5 }\nlayout = \"schuler\"\n");
  const fs::path depfile = dir / "deps.d", stamp = dir / "all.stamp";
  const json report = run_json({"build", (folder / "m.toml").string(), "--depfile", depfile.string(), "--stamp", stamp.string()});
  EXPECT_EQ(read_bytes(depfile), dir.path().string() + "/all.stamp: \\\n  " + dir.path().string() + "/my\\ assets/m.toml \\\n  " +
                                     dir.path().string() + "/my\\ assets/k\\ d.png\n");
  EXPECT_TRUE(fs::exists(stamp));
  ASSERT_EQ(report["jobs"].size(), 1u);
  const json& job = report["jobs"][0];
  EXPECT_EQ(job["name"], "material:brick");
  EXPECT_EQ(job["outcome"], "built");
  EXPECT_EQ(job["reason"], "no earlier build");
  EXPECT_EQ(job["inputs"], json::array({(folder / "k d.png").string()}));
  EXPECT_EQ(job["outputs"], json::array({(folder / "out/materials/brick_a.png").string(), (folder / "out/materials/brick_b.png").string(),
                                         (folder / "out/materials/brick.validation.json").string(),
                                         (folder / "out/materials/brick_preview.png").string()}));
  EXPECT_GE(job["seconds"].get<double>(), 0);
  EXPECT_EQ(job["details"]["size"], json::array({2, 2}));
  EXPECT_EQ(job["details"]["validation"]["checked"], 4);
  EXPECT_EQ(job["details"]["validation"]["passed"], true);
  EXPECT_FALSE(job["details"].contains("conversion"));  // the schuler layout takes spec-gloss as given

  // Without --stamp the targets are the outputs; --quiet prints nothing; not on a terminal, each
  // job's start and end is one line.
  const RunResult quiet = matbake({"build", (folder / "m.toml").string(), "--force", "--quiet", "--depfile", depfile.string()});
  EXPECT_EQ(quiet.out + quiet.err, "");
  std::string first_output = (folder / "out/materials/brick_a.png").string();
  first_output.replace(first_output.find(' '), 1, "\\ ");
  EXPECT_EQ(read_bytes(depfile).rfind(first_output + " ", 0), 0u) << read_bytes(depfile);
  const RunResult plain = matbake({"build", (folder / "m.toml").string(), "--force"});
  EXPECT_EQ(plain.err.rfind("material:brick started (1 of 1)\n[1/1] material:brick built (", 0), 0u) << plain.err;
}

// On a terminal (script(1) gives the build one), stderr shows the bar with done/total, the share of
// work, the ETA and the running job with its stage.
TEST(CliBuild, ProgressBarOnATerminal) {
  const RunResult which = run("/bin/sh", {"-c", "command -v script"});
  if (which.exit_code != 0) GTEST_SKIP() << "script(1) is not installed";
  TempDir dir;
  write_raw(dir / "grey.png", 512, 512, 1, "uint8", std::vector<double>(512 * 512, 120));
  std::string manifest;
  for (int m = 0; m < 40; ++m) {
    manifest += "[materials.m" + std::to_string(m) + "]\nsources = { base_color = \"grey.png\", metallic = 0.0, roughness = 0." +
                std::to_string(10 + m) + " }\nlayout = \"gltf-orm\"\n";
  }
  write_bytes(dir / "m.toml", manifest);
  const std::string command = std::string(MATBAKE_EXE) + " build '" + (dir / "m.toml").string() + "' --jobs 1";
  const RunResult r = run(which.out.substr(0, which.out.find('\n')), {"-qec", command, "/dev/null"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\\] [0-9]+/40 +[0-9]+% ETA [0-9]+:[0-9]{2}  material:m[0-9]+ \\((decoding "
                                                  "sources|validating|writing textures), [0-9]+ s\\)")))
      << r.out;
  EXPECT_EQ(r.out.find("material:m1 built"), std::string::npos);  // no per-job lines on a terminal
  EXPECT_NE(r.out.find("built 40, up to date 0, failed 0"), std::string::npos) << r.out;
}

// Ninja runs the plan's edges; a changed source re-runs its material and nothing else.
TEST(CliPlan, NinjaBuildsTheEdges) {
  const RunResult which = run("/bin/sh", {"-c", "command -v ninja"});
  if (which.exit_code != 0) GTEST_SKIP() << "ninja is not installed";
  const std::string ninja_exe = which.out.substr(0, which.out.find('\n'));
  TempDir dir;
  copy_example(dir.path(), true);
  const RunResult plan = matbake({"plan", (dir / "showroom.toml").string(), "-o", (dir / "build.ninja").string()});
  ASSERT_EQ(plan.exit_code, 0) << plan.err;
  EXPECT_EQ(plan.out, (dir / "build.ninja").string() + ": 6 edges\n");
  RunResult ninja = run(ninja_exe, {"-C", dir.path().string()});
  ASSERT_EQ(ninja.exit_code, 0) << ninja.out << ninja.err;
  EXPECT_NE(ninja.out.find("[6/6]"), std::string::npos) << ninja.out;
  EXPECT_TRUE(fs::exists(dir / "out/showroom.glb"));
  ninja = run(ninja_exe, {"-C", dir.path().string()});
  EXPECT_NE(ninja.out.find("no work to do"), std::string::npos) << ninja.out;
  write_raw(dir / "textures/rubber_albedo.png", 2, 2, 1, "uint8", {50, 51, 52, 53});
  ninja = run(ninja_exe, {"-C", dir.path().string()});
  EXPECT_NE(ninja.out.find("[1/2] matbake material:rubber"), std::string::npos) << ninja.out;
  EXPECT_NE(ninja.out.find("[2/2] matbake scene:showroom"), std::string::npos) << ninja.out;
}

// The manifest's max_pixels is its jobs' limit, in a build and in the jobs Ninja runs; the command
// line's --max-pixels wins; the refusal names the key in the manifest's words.
TEST(CliBuild, TheManifestsPixelLimitHoldsInEveryJobAndTheFlagWins) {
  TempDir dir;
  write_raw(dir / "t.png", 16, 16, 3, "uint8", std::vector<double>(16 * 16 * 3, 100));
  write_bytes(dir / "m.toml", "max_pixels = 100\n[materials.a]\nsources = { kd = \"t.png\", ks = 0.04, gloss = 0.5 }\n"
                              "layout = \"gltf-orm\"\n");
  const RunResult refused = matbake({"build", (dir / "m.toml").string()});
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find((dir / "t.png").string() + ": 16x16 is more than the limit of 100 pixels (max_pixels raises it)"),
            std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir / "out/materials/a_orm.png"));
  const RunResult raised = matbake({"--max-pixels", "256", "build", (dir / "m.toml").string()});
  EXPECT_EQ(raised.exit_code, 0) << raised.err;
  EXPECT_TRUE(fs::exists(dir / "out/materials/a_orm.png"));

  const RunResult which = run("/bin/sh", {"-c", "command -v ninja"});
  if (which.exit_code != 0) GTEST_SKIP() << "ninja is not installed";
  fs::remove_all(dir / "out");
  ASSERT_EQ(matbake({"plan", (dir / "m.toml").string(), "-o", (dir / "build.ninja").string()}).exit_code, 0);
  const RunResult ninja = run(which.out.substr(0, which.out.find('\n')), {"-C", dir.path().string()});
  EXPECT_NE(ninja.exit_code, 0);
  EXPECT_NE((ninja.out + ninja.err).find("more than the limit of 100 pixels"), std::string::npos) << ninja.out << ninja.err;
}

bool has(const std::vector<std::string>& args, const std::string& arg) {
  return std::find(args.begin(), args.end(), arg) != args.end();
}

// plan --format slurm's scripts run through the stand-in: the array and the scene's dependency on
// each of its tasks as sbatch is given them, the outputs those of a local build byte for byte; then
// nothing to submit, and after a source changes, its material and the scene only.
TEST(CliPlan, SlurmSubmissionBuildsWhatALocalBuildBuilds) {
  TempDir dir;
  fs::create_directories(dir / "cluster");
  fs::create_directories(dir / "local");
  copy_example(dir / "cluster", true);
  copy_example(dir / "local", true);
  const fs::path sbatch = stand_in_sbatch(dir.path()), slurm = dir / "cluster/slurm";
  const std::string manifest = (dir / "cluster/showroom.toml").string();
  const json planned = run_json({"plan", manifest, "--format", "slurm", "-o", slurm.string()});
  EXPECT_EQ(planned["array"]["jobs"], json({"material:glass", "material:gold_trim", "material:painted_metal",
                                            "material:rubber", "material:wood"}));
  ASSERT_EQ(planned["scenes"].size(), 1u);
  EXPECT_EQ(planned["scenes"][0]["after_tasks"], json({0, 1, 2, 3, 4}));
  const auto submit = [&] { return run("/bin/bash", {(slurm / "submit.sh").string()}, {"SBATCH=" + sbatch.string()}); };
  RunResult r = submit();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "matbake: submitted 5 material jobs (one array), 1 scene job; 0 up to date: array 101 scenes 102\n");
  auto calls = sbatch_calls(dir.path());
  ASSERT_EQ(calls.size(), 2u);
  const std::string mem = "--mem=" + std::to_string(planned["array"]["memory_mb"].get<int>()) + "M";
  for (const char* arg : {"--parsable", "--array=0-4", "--cpus-per-task=1"}) EXPECT_TRUE(has(calls[0], arg)) << arg;
  EXPECT_TRUE(has(calls[0], mem));
  EXPECT_TRUE(has(calls[1], "--dependency=afterok:101_0:101_1:101_2:101_3:101_4"));
  EXPECT_TRUE(has(calls[1], "--kill-on-invalid-dep=yes"));
  EXPECT_EQ(calls[1].back(), "scene:showroom");
  ASSERT_EQ(matbake({"build", (dir / "local/showroom.toml").string(), "--quiet"}).exit_code, 0);
  EXPECT_EQ(outputs_under(dir / "cluster/out"), outputs_under(dir / "local/out"));

  r = matbake({"plan", manifest, "--format", "slurm", "-o", slurm.string()});
  EXPECT_EQ(r.out, (slurm / "submit.sh").string() + ": 0 material jobs (one array), 0 scene jobs; 6 up to date\n");
  EXPECT_EQ(submit().out, "matbake: nothing to submit: 0 material jobs (one array), 0 scene jobs; 6 up to date\n");
  EXPECT_EQ(sbatch_calls(dir.path()).size(), 2u);
  r = matbake({"plan", manifest, "--format", "slurm", "-o", slurm.string(), "--dry-run"});  // says so, writes nothing
  EXPECT_EQ(r.out, "nothing to submit: 0 material jobs (one array), 0 scene jobs; 6 up to date\n");

  fs::copy_file(dir / "cluster/textures/painted_metal_albedo.png", dir / "cluster/textures/rubber_albedo.png",
                fs::copy_options::overwrite_existing);
  const json again = run_json({"plan", manifest, "--format", "slurm", "-o", slurm.string()});
  EXPECT_EQ(again["array"]["jobs"], json({"material:rubber"}));
  EXPECT_EQ(again["scenes"][0]["after_tasks"], json({0}));
  EXPECT_EQ(again["up_to_date"], 4);
}

// Each [cluster] parameter from either door (its example as a flag, or as a manifest key) reaches
// the submission; a flag wins over the manifest; a dry run prints sbatch's lines and writes nothing.
TEST(CliPlan, SlurmParametersFromBothDoors) {
  TempDir dir;
  copy_example(dir.path());
  const std::string manifest = (dir / "showroom.toml").string(), slurm = (dir / "slurm").string();
  const std::string original = read_bytes(manifest);
  for (const params::Spec* spec : pipeline::cluster_params().specs()) {
    const json example = spec->kind == params::Kind::integer ? json(std::stoll(spec->example)) : json(spec->example);
    if (!spec->manifest_only) {
      const json j = run_json({"plan", manifest, "--format", "slurm", "-o", slurm, "--dry-run",
                               params::flag_name(*spec, ""), spec->example});
      EXPECT_EQ(j["cluster"][spec->name], example) << spec->name << " as a flag";
    }
    write_bytes(manifest, original + "\n[cluster]\n" + spec->name + " = " + example.dump() + "\n");
    const json j = run_json({"plan", manifest, "--format", "slurm", "-o", slurm, "--dry-run"});
    EXPECT_EQ(j["cluster"][spec->name], example) << spec->name << " in the manifest";
    write_bytes(manifest, original);
  }
  write_bytes(manifest, original + "\n[cluster]\npartition = \"gpu\"\ncpus = 3\n");
  const RunResult r = matbake({"plan", manifest, "--format", "slurm", "-o", slurm, "--dry-run", "--partition", "cpu", "-j", "4"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("sbatch --parsable --job-name=matbake-materials --array=0-4 --mem=", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("--cpus-per-task=4 --partition=cpu --output=" + slurm + "/logs/material-%a.log " + slurm + "/job.sh\n"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--dependency=afterok:\"$array\"_0:\"$array\"_1:\"$array\"_2:\"$array\"_3:\"$array\"_4 "),
            std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(slurm));
}

TEST(CliPlan, SlurmRefusesBadValuesAndWritesNothing) {
  TempDir dir;
  copy_example(dir.path());
  const std::string manifest = (dir / "showroom.toml").string(), slurm = (dir / "slurm").string();
  RunResult r = matbake({"plan", manifest, "--format", "slurm", "-o", slurm, "--partition", "a b"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "matbake: error: --partition: 'a b': letters, digits, '_', '-', '.' and ',' only (see matbake --help)\n");
  write_bytes(manifest, read_bytes(manifest) + "\n[cluster]\ntime_limit = \"soon\"\n");
  r = matbake({"plan", manifest, "--format", "slurm", "-o", slurm});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(manifest + ":"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cluster.time_limit: minutes, MM:SS, HH:MM:SS or D-HH:MM:SS"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(slurm));
  // The output folder is a file (here the scene): refused, the file untouched.
  fs::create_directories(dir / "again");
  copy_example(dir / "again");
  const std::string scene = read_bytes(dir / "again/showroom.gltf");
  r = matbake({"plan", (dir / "again/showroom.toml").string(), "--format", "slurm", "-o", (dir / "again/showroom.gltf").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(read_bytes(dir / "again/showroom.gltf"), scene);
}

// After jobs ran elsewhere (here: one at a time with --only), --status names the failed one with its
// error line, the scene that waits for it, and the counts; exit 1 until the failure is built again.
TEST(CliBuild, StatusNamesFailedJobsAndWhatWaitsForThem) {
  TempDir dir;
  copy_example(dir.path(), true);
  const std::string manifest = (dir / "showroom.toml").string();
  ASSERT_EQ(matbake({"build", manifest, "--quiet"}).exit_code, 0);
  RunResult r = matbake({"build", manifest, "--status"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "up to date 6, failed 0, not built 0\n");
  const std::string good = read_bytes(dir / "textures/rubber_albedo.png");
  write_bytes(dir / "textures/rubber_albedo.png", good.substr(0, 100));
  EXPECT_EQ(matbake({"build", manifest, "--only", "material:rubber", "--quiet"}).exit_code, 1);
  r = matbake({"build", manifest, "--status"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "not built scene:showroom: waits for material:rubber, which failed\nup to date 4, failed 1, not built 1\n");
  const std::string first_line = r.err.substr(0, r.err.find('\n'));
  EXPECT_NE(first_line.find("rubber_albedo.png: "), std::string::npos) << r.err;
  EXPECT_EQ(first_line.substr(first_line.size() - 18), " (material:rubber)") << r.err;
  const json j = run_json({"build", manifest, "--status"}, 1);
  EXPECT_EQ(j["counts"], json({{"up_to_date", 4}, {"failed", 1}, {"not_built", 1}}));
  write_bytes(dir / "textures/rubber_albedo.png", good);
  ASSERT_EQ(matbake({"build", manifest, "--quiet"}).exit_code, 0);
  EXPECT_EQ(matbake({"build", manifest, "--status"}).out, "up to date 6, failed 0, not built 0\n");
  EXPECT_FALSE(fs::exists(dir / "out/.matbake/material-rubber.failed"));
}

// A build of many large materials killed mid-way by SIGINT, then by SIGTERM: exit 128 + signal,
// no temporary file anywhere, every finished output complete; the next run builds only the rest.
TEST(CliBuild, InterruptKeepsFinishedOutputsAndNoTemporaryFiles) {
  TempDir dir;
  constexpr int kSize = 1024, kMaterials = 12;
  std::vector<double> noise(std::size_t(kSize) * kSize * 3);
  std::uint32_t state = 12345;
  for (double& v : noise) {
    state = state * 1664525u + 1013904223u;
    v = double(state >> 24);
  }
  write_raw(dir / "noise.png", kSize, kSize, 3, "uint8", noise);
  std::string manifest;
  for (int m = 0; m < kMaterials; ++m) {
    manifest += "[materials.m" + std::to_string(100 + m) + "]\nsources = { base_color = \"noise.png\", metallic = 0.0, roughness = " +
                std::to_string(0.3 + 0.01 * m) + " }\nlayout = \"gltf-orm\"\n"
                "validate = { enabled = false }\n";
  }
  write_bytes(dir / "m.toml", manifest);
  for (int signal : {SIGINT, SIGTERM}) {
    const fs::path state_folder = dir / "out/.matbake";
    fs::remove_all(dir / "out");
    const std::string exe = MATBAKE_EXE, manifest_path = (dir / "m.toml").string();
    std::vector<char*> argv = {const_cast<char*>(exe.c_str()), const_cast<char*>("build"), const_cast<char*>(manifest_path.c_str()),
                               const_cast<char*>("--quiet"), nullptr};
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv.data(), environ), 0);
    // Wait for the first finished job's stamp (not the temporary file it is written through, nor the
    // folder's owner record), then interrupt.
    const auto is_stamp = [](const fs::path& p) { return p.filename().string().rfind("material-", 0) == 0; };
    const auto stamps = [&] {
      std::size_t n = 0;
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(state_folder, ec)) n += is_stamp(e.path());
      return n;
    };
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(300);
    while (std::chrono::steady_clock::now() < deadline && stamps() == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    kill(pid, signal);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    ASSERT_EQ(WEXITSTATUS(status), 128 + signal) << "the build ended before the signal: make it larger";
    EXPECT_EQ(temporary_files_under(dir.path()), std::vector<std::string>{});
    std::size_t finished = 0;
    for (const auto& e : fs::directory_iterator(state_folder)) {
      ASSERT_NE(e.path().filename().string()[0], '.') << e.path();
      if (!is_stamp(e.path())) continue;
      ++finished;
      const json stamp = json::parse(read_bytes(e.path()));
      for (const json& out : stamp["outputs"]) {
        const std::string path = out["path"];  // relative to the output folder
        const RawImage image = read_raw(dir / "out" / path);
        EXPECT_EQ(image.width, path.ends_with("_preview.png") ? preview::Options{}.cell_size : kSize) << path;
      }
    }
    EXPECT_GE(finished, 1u);
    EXPECT_LT(finished, std::size_t(kMaterials));
    const json rest = run_json({"build", manifest_path});
    EXPECT_EQ(rest["up_to_date"], finished);
    EXPECT_EQ(rest["built"], kMaterials - finished);
    // The interrupted run wrote no log of what it made; the next one logs its finished jobs too
    // (from their stamps), so their files can be found stale later.
    EXPECT_EQ(json::parse(read_bytes(state_folder / "made.json"))["jobs"].size(), std::size_t(kMaterials));
  }
}

// Twenty `build --only` runs at once in one output folder (Ninja edges, Slurm array tasks): each
// job's files are in the log of files made, none lost to another run's write.
TEST(CliBuild, RunsAtOnceKeepEveryJobInTheLogOfFilesMade) {
  TempDir dir;
  constexpr int kMaterials = 20;
  write_raw(dir / "grey.png", 4, 4, 3, "uint8", std::vector<double>(4 * 4 * 3, 128.0));
  std::string manifest;
  for (int m = 0; m < kMaterials; ++m) {
    manifest += "[materials.m" + std::to_string(m) + "]\nsources = { base_color = \"grey.png\", metallic = 0.0, roughness = 0.5 }\n"
                "layout = \"gltf-orm\"\nvalidate = { enabled = false }\n";
  }
  write_bytes(dir / "m.toml", manifest);
  const std::string exe = MATBAKE_EXE, manifest_path = (dir / "m.toml").string();
  std::vector<pid_t> runs;
  for (int m = 0; m < kMaterials; ++m) {
    const std::string only = "material:m" + std::to_string(m);
    std::vector<char*> argv = {const_cast<char*>(exe.c_str()), const_cast<char*>("build"), const_cast<char*>(manifest_path.c_str()),
                               const_cast<char*>("--only"), const_cast<char*>(only.c_str()), const_cast<char*>("--quiet"), nullptr};
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv.data(), environ), 0);
    runs.push_back(pid);
  }
  for (pid_t pid : runs) {
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  const json log = json::parse(read_bytes(dir / "out/.matbake/made.json"));
  ASSERT_EQ(log["jobs"].size(), std::size_t(kMaterials)) << log.dump(1);
  for (int m = 0; m < kMaterials; ++m) {
    const std::string job = "material:m" + std::to_string(m);
    const json stamp = json::parse(read_bytes(dir / ("out/.matbake/material-m" + std::to_string(m) + ".json")));
    json written = json::object();  // what the job's stamp says it wrote
    for (const json& out : stamp["outputs"]) {
      written[out["path"].get<std::string>()] = out["hash"];
    }
    EXPECT_EQ(written.size(), 3u);  // its texture, its validation report, its ball
    EXPECT_EQ(log["jobs"][job], written) << job;
  }
}

// examples/showroom.gltf and .bin are what examples/scene/make_example_scene writes.
TEST(ExampleScene, GeneratorWritesTheCommittedFiles) {
  TempDir dir;
  const RunResult r = run(MATBAKE_EXAMPLE_SCENE_EXE, {dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_bytes(dir / "showroom.gltf"), read_bytes(kExamples / "showroom.gltf"));
  EXPECT_EQ(read_bytes(dir / "showroom.bin"), read_bytes(kExamples / "showroom.bin"));
}

}  // namespace
}  // namespace matbake::test

namespace matbake::test {
namespace {

// The report page is written inside the output folder only (--report=FILE elsewhere is refused,
// nothing built); `report = true` in the manifest writes OUT/report.html on every build.
TEST(CliBuild, TheReportPageGoesInsideTheOutputFolder) {
  TempDir dir;
  write_raw(dir / "a.png", 4, 4, 3, "uint8", std::vector<double>(48, 120));
  const std::string material = "[materials.a]\nsources = { base_color = \"a.png\", metallic = 0.0, roughness = 0.5 }\n"
                               "layout = \"gltf-orm\"\n";
  write_bytes(dir / "m.toml", material);
  RunResult r = matbake({"build", (dir / "m.toml").string(), "--report=" + (dir / "elsewhere.html").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "matbake: error: " + (dir / "elsewhere.html").string() + ": the report page goes inside the output folder (" +
                       (dir / "out").string() + ")\n");
  EXPECT_FALSE(fs::exists(dir / "elsewhere.html"));
  write_bytes(dir / "m.toml", "report = true\n" + material);
  r = matbake({"build", (dir / "m.toml").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string page = read_bytes(dir / "out/report.html");
  EXPECT_NE(page.find("<section id=\"material:a\"><h3>a</h3>"), std::string::npos) << page;
  EXPECT_NE(page.find("<img src=\"materials/a_base_color.png\""), std::string::npos) << page;
  EXPECT_NE(page.find("validation: 0 of 16 texels flagged"), std::string::npos) << page;
  EXPECT_EQ(page.find("<script"), std::string::npos);
  // A build tool's one-job runs leave the whole build's page alone; --report with --only is refused.
  const std::string before = read_bytes(dir / "out/report.html");
  r = matbake({"build", (dir / "m.toml").string(), "--only", "material:a", "--force"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_bytes(dir / "out/report.html"), before);
  r = matbake({"build", (dir / "m.toml").string(), "--only", "material:a", "--report"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "matbake: error: --only excludes --report (see matbake --help)\n");
}

}  // namespace
}  // namespace matbake::test
