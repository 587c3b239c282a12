// Issue "Safe by construction": what a build writes, deletes and runs goes through one gate. Each
// case plants what an attacker or a careless user would (a tampered output folder, an option naming
// an input, a hostile path in a generated script) and checks every file outside the output folder
// byte for byte before and after.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <thread>

#include "matbake/output_gate.hpp"
#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/sbatch.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Every regular file under `root` outside `skip` (the output folder), with its bytes.
std::map<std::string, std::string> files_outside(const fs::path& root, const fs::path& skip) {
  std::map<std::string, std::string> files;
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator(); ++it) {
    if (it->path() == skip) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && !it->is_symlink()) files[it->path().string()] = read_bytes(it->path());
  }
  return files;
}

// A manifest of one material from a 2×2 PNG into the glTF ORM layout; the user's own files beside it.
struct Library {
  TempDir dir;
  fs::path manifest = dir / "m.toml";
  fs::path out = dir / "out";
  Library() {
    write_raw(dir / "kd.png", 2, 2, 3, "uint8", {100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210});
    write_bytes(manifest, "output = \"out\"\n[materials.m0]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n"
                          "layout = \"gltf-orm\"\n");
    fs::create_directories(dir / "u");
    write_bytes(dir / "u/notes.txt", "the user's notes");
  }
  RunResult build(std::vector<std::string> more = {}) const {
    std::vector<std::string> args{"build", manifest.string()};
    args.insert(args.end(), more.begin(), more.end());
    return matbake(args);
  }
};

// What made.json records of a file (the XXH64 of its bytes): public, so anyone can forge an entry.
std::string xxh64_of(const fs::path& file) {
  const std::string bytes = read_bytes(file);
  return hash_bytes({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()});
}

// made.json entries that name files outside the output folder (`..`, absolute, a job the manifest no
// longer has, through a link inside OUT) or a live output another way, each with the file's true
// hash: no file is removed, each entry is one warning, and the live output stays.
TEST(Gate, TheCleanerRemovesOnlyWhatItProvablyMade) {
  Library lib;
  ASSERT_EQ(lib.build().exit_code, 0);
  const std::string notes_hash = xxh64_of(lib.dir / "u/notes.txt");
  const std::string orm_hash = xxh64_of(lib.out / "materials/m0_orm.png");
  fs::create_directory_symlink(lib.dir / "u", lib.out / "linked");
  json log = json::parse(read_bytes(lib.out / ".matbake/made.json"));
  log["stale"] = {{"../u/notes.txt", notes_hash},
                  {(lib.dir / "u/notes.txt").string(), notes_hash},
                  {"linked/notes.txt", notes_hash},
                  {"materials/./m0_orm.png", orm_hash},
                  {"../m.toml", xxh64_of(lib.manifest)},
                  {"../kd.png", xxh64_of(lib.dir / "kd.png")}};
  log["jobs"]["material:gone"] = {{"../../" + lib.dir.path().filename().string() + "/u/notes.txt", notes_hash}};
  write_bytes(lib.out / ".matbake/made.json", log.dump());
  const auto before = files_outside(lib.dir.path(), lib.out);
  const RunResult r = lib.build();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(files_outside(lib.dir.path(), lib.out), before);
  EXPECT_TRUE(fs::exists(lib.out / "materials/m0_orm.png"));
  EXPECT_EQ(read_bytes(lib.dir / "u/notes.txt"), "the user's notes");
  EXPECT_EQ(r.out.find("removed "), std::string::npos) << r.out;
  for (const char* entry : {"'../u/notes.txt'", "'linked/notes.txt'", "'materials/./m0_orm.png'", "'../m.toml'"}) {
    EXPECT_NE(r.err.find(std::string("matbake: warning: made.json lists ") + entry), std::string::npos) << entry << "\n" << r.err;
  }
  // Each refusal is said once: the entries are forgotten.
  const RunResult again = lib.build();
  EXPECT_EQ(again.err.find("made.json lists"), std::string::npos) << again.err;
  EXPECT_NE(again.out.find("nothing to do"), std::string::npos) << again.out;
}

// --depfile, --stamp and plan -o never overwrite a file the build reads or writes, nor matbake's
// state: a usage error naming the option, and every file as it was.
TEST(Gate, SideOutputsNeverOverwriteInputsOutputsOrState) {
  Library lib;
  ASSERT_EQ(lib.build().exit_code, 0);
  const std::string manifest = lib.manifest.string(), source = (lib.dir / "kd.png").string(),
                    output = (lib.out / "materials/m0_orm.png").string(), log = (lib.out / ".matbake/made.json").string();
  const std::vector<std::vector<std::string>> cases = {
      {"build", manifest, "--depfile", manifest},
      {"build", manifest, "--stamp", source},
      {"build", manifest, "--depfile", output},
      {"build", manifest, "--stamp", log},
      {"build", manifest, "--depfile", (lib.dir / "d").string(), "--stamp", (lib.dir / "d").string()},
      {"plan", manifest, "-o", manifest},
      {"plan", manifest, "-o", output},
      {"plan", manifest, "-o", source},
  };
  for (const auto& args : cases) {
    const auto before = files_outside(lib.dir.path(), lib.dir / "none");
    const RunResult r = matbake(args);
    EXPECT_EQ(r.exit_code, 2) << args[2] << " " << args[3] << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("matbake: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(args.back() + ": is "), std::string::npos) << r.err;
    EXPECT_EQ(files_outside(lib.dir.path(), lib.dir / "none"), before) << args[2] << " " << args[3];
  }
}

// Stamps, made.json and failure records are read as hostile input: a wrong type, a huge file or a
// link is one warning naming the file; the job rebuilds and the build succeeds; --status works.
TEST(Gate, StateFilesAreReadAsHostileInput) {
  Library lib;
  ASSERT_EQ(lib.build().exit_code, 0);
  const fs::path stamp = lib.out / ".matbake/material-m0.json", made = lib.out / ".matbake/made.json";
  json s = json::parse(read_bytes(stamp));
  s["outputs"][0]["size"] = "big";
  write_bytes(stamp, s.dump());
  write_bytes(made, R"({"form": 1, "jobs": {"material:m0": {"materials/m0_orm.png": 7}}, "stale": {}})");
  const RunResult status = matbake({"build", lib.manifest.string(), "--status"});
  EXPECT_EQ(status.exit_code, 0) << status.err;
  EXPECT_NE(status.out.find("not built material:m0: stamp refused: " + stamp.string() + " is not one matbake wrote"),
            std::string::npos) << status.out;
  const RunResult r = lib.build();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("matbake: warning: " + stamp.string() + " is not one matbake wrote"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("matbake: warning: " + made.string() + " has a file without its hash"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("built 1"), std::string::npos) << r.out;
  EXPECT_NE(lib.build().out.find("nothing to do"), std::string::npos);

  // 100 MB of made.json (sparse, so the test costs nothing): refused by its size, not read.
  {
    const int fd = ::open(made.c_str(), O_WRONLY | O_TRUNC);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, 100 << 20), 0);
    ::close(fd);
  }
  const RunResult huge = lib.build({"--force"});
  EXPECT_EQ(huge.exit_code, 0) << huge.err;
  EXPECT_NE(huge.err.find(made.string() + " is 104857600 bytes, over the 64 MiB"), std::string::npos) << huge.err;

  // A truncated stamp, and a stamp that is a link to a file elsewhere: refused, rebuilt.
  const std::string whole = read_bytes(stamp);
  write_bytes(stamp, whole.substr(0, whole.size() / 2));
  const RunResult truncated = lib.build();
  EXPECT_EQ(truncated.exit_code, 0) << truncated.err;
  EXPECT_NE(truncated.err.find(stamp.string() + " is not valid JSON"), std::string::npos) << truncated.err;
  write_bytes(lib.dir / "u/stamp.json", read_bytes(stamp));
  fs::remove(stamp);
  fs::create_symlink(lib.dir / "u/stamp.json", stamp);
  const RunResult linked_stamp = lib.build();
  EXPECT_NE(linked_stamp.err.find(stamp.string() + " is a link"), std::string::npos) << linked_stamp.err;
  EXPECT_NE(linked_stamp.out.find("built 1"), std::string::npos) << linked_stamp.out;

  // A lock that is a dangling link: its target is never made.
  fs::remove(lib.out / ".matbake/made.lock");
  fs::create_symlink(lib.dir / "u/planted", lib.out / ".matbake/made.lock");
  const RunResult linked = lib.build({"--force"});
  EXPECT_EQ(linked.exit_code, 0) << linked.err;
  EXPECT_FALSE(fs::exists(lib.dir / "u/planted"));
  EXPECT_NE(linked.err.find("made.lock is a link"), std::string::npos) << linked.err;
}

std::string program_on_path(const std::string& name) {
  const RunResult which = run("/bin/sh", {"-c", "command -v " + name});
  return which.exit_code == 0 ? which.out.substr(0, which.out.find('\n')) : std::string();
}

// A manifest in a folder whose name is shell or Ninja syntax: the Ninja plan builds it (or, where a
// depfile as Ninja reads it cannot hold the name, refuses it: exit 2, nothing written) and the Slurm
// scripts submit it (through a stand-in sbatch); nothing the name smuggles in runs.
TEST(Gate, GeneratedScriptsHoldHostilePathsAsData) {
  const std::string ninja = program_on_path("ninja");
  if (ninja.empty()) GTEST_SKIP() << "ninja is not installed";
  TempDir dir;
  const fs::path sbatch = stand_in_sbatch(dir.path());
  const std::vector<std::string> names = {"assets $(touch PWNED)", "assets `touch PWNED`", "q\"uote;semi&amp",
                                          "-dash", "dollar$array $(id)", "colon:a b", "non-utf8 \xff\xfe", "it's"};
  for (const std::string& name : names) {
    const fs::path folder = dir / name;
    fs::create_directories(folder);
    write_raw(folder / "kd.png", 2, 2, 3, "uint8", {100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210});
    write_bytes(folder / "m.toml", "output = \"out\"\n[materials.m0]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n"
                                   "layout = \"gltf-orm\"\n");
    const RunResult plan = matbake({"plan", (folder / "m.toml").string(), "-o", (folder / "build.ninja").string()});
    if (name.find_first_of("`\";'") != std::string::npos) {
      EXPECT_EQ(plan.exit_code, 2) << name;
      EXPECT_NE(plan.err.find("which a depfile (as Ninja reads it) cannot hold"), std::string::npos) << plan.err;
      EXPECT_FALSE(fs::exists(folder / "build.ninja"));
    } else {
      ASSERT_EQ(plan.exit_code, 0) << name << ": " << plan.err;
      const RunResult built = run(ninja, {"-C", folder.string()});
      EXPECT_EQ(built.exit_code, 0) << name << ": " << built.out << built.err;
      EXPECT_TRUE(fs::exists(folder / "out/materials/m0_orm.png")) << name;
      EXPECT_NE(run(ninja, {"-C", folder.string()}).out.find("no work to do"), std::string::npos) << name;
      fs::remove_all(folder / "out");
    }

    const fs::path slurm = folder / ("slurm " + name);
    const RunResult planned = matbake({"plan", (folder / "m.toml").string(), "--format", "slurm", "-o", slurm.string()});
    ASSERT_EQ(planned.exit_code, 0) << name << ": " << planned.err;
    EXPECT_EQ(run("/bin/bash", {"-n", (slurm / "submit.sh").string()}).exit_code, 0) << name;
    const RunResult submitted = run("/bin/bash", {(slurm / "submit.sh").string()}, {"SBATCH=" + sbatch.string()});
    EXPECT_EQ(submitted.exit_code, 0) << name << ": " << submitted.err;
    EXPECT_TRUE(fs::exists(folder / "out/materials/m0_orm.png")) << name;
  }
  for (const auto& e : fs::recursive_directory_iterator(dir.path())) EXPECT_NE(e.path().filename(), "PWNED") << e.path();
  EXPECT_FALSE(fs::exists("PWNED"));
}

// What a generated file cannot hold (a line break anywhere, '|' in a Ninja path) is one error line,
// exit 2, and nothing written.
TEST(Gate, UnrepresentablePathsAreRefusedBeforeAnythingIsWritten) {
  TempDir dir;
  for (const std::string& name : {std::string("new\nline"), std::string("pipe|name")}) {
    const fs::path folder = dir / name;
    fs::create_directories(folder);
    write_bytes(folder / "m.toml", "output = \"out\"\n[materials.m0]\nsources = { base_color = 0.5, metallic = 0.0, roughness = 0.5 }\n"
                                   "layout = \"gltf-orm\"\n");
    const auto before = list_folder(folder);
    const RunResult ninja = matbake({"plan", (folder / "m.toml").string(), "-o", (folder / "build.ninja").string()});
    EXPECT_EQ(ninja.exit_code, 2) << ninja.err;
    EXPECT_EQ(std::count(ninja.err.begin(), ninja.err.end(), '\n'), 1) << ninja.err;
    EXPECT_NE(ninja.err.find(name.find('|') != std::string::npos ? "holds '|'" : "holds a line break"), std::string::npos) << ninja.err;
    const RunResult slurm = matbake({"plan", (folder / "m.toml").string(), "--format", "slurm", "-o", (folder / "s").string()});
    if (name.find('\n') != std::string::npos) {
      EXPECT_EQ(slurm.exit_code, 2) << slurm.err;
      EXPECT_NE(slurm.err.find("holds a line break; a shell script cannot hold it"), std::string::npos) << slurm.err;
      EXPECT_EQ(list_folder(folder), before);
    } else {
      EXPECT_EQ(slurm.exit_code, 0) << slurm.err;  // the shell holds '|' in quotes
    }
  }
}

// A texture set that a material rule now matches is built by Ninja: the plan's own edge depends on
// the folders rules scan, so a new file there writes the plan again and the new edge runs.
TEST(Gate, NinjaBuildsANewTextureSetARuleMatches) {
  const std::string ninja = program_on_path("ninja");
  if (ninja.empty()) GTEST_SKIP() << "ninja is not installed";
  TempDir dir;
  fs::create_directories(dir / "t");
  write_raw(dir / "t/a_BaseColor.png", 2, 2, 3, "uint8", {100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210});
  write_bytes(dir / "m.toml", "output = \"out\"\n[material_rules.lib]\nmatch = \"t/{name}_BaseColor.png\"\n"
                              "sources = { base_color = \"t/{name}_BaseColor.png\", metallic = 0.0, roughness = 0.5 }\nlayout = \"gltf-orm\"\n");
  ASSERT_EQ(matbake({"plan", (dir / "m.toml").string(), "-o", (dir / "build.ninja").string()}).exit_code, 0);
  ASSERT_EQ(run(ninja, {"-C", dir.path().string()}).exit_code, 0);
  EXPECT_TRUE(fs::exists(dir / "out/materials/a_orm.png"));
  // Folder times have a granularity: the new entry must change the folder's time.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  fs::copy_file(dir / "t/a_BaseColor.png", dir / "t/b_BaseColor.png");
  const RunResult again = run(ninja, {"-C", dir.path().string()});
  EXPECT_EQ(again.exit_code, 0) << again.out << again.err;
  EXPECT_TRUE(fs::exists(dir / "out/materials/b_orm.png")) << again.out;
  EXPECT_NE(run(ninja, {"-C", dir.path().string()}).out.find("no work to do"), std::string::npos);
}

// Two manifests with one output folder (two CMake targets with one OUTPUT_DIR, the default out/):
// the second is refused, naming the first, and the first's outputs stay byte for byte. When both
// say shared_output = true, each keeps its own state and cleans only its own files.
TEST(Gate, AnOutputFolderBelongsToOneManifestUnlessShared) {
  Library lib;
  write_bytes(lib.dir / "b.toml", "output = \"out\"\n[materials.b0]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.2 }\n"
                                  "layout = \"gltf-orm\"\n");
  ASSERT_EQ(lib.build().exit_code, 0);
  const auto before = files_outside(lib.dir.path(), lib.dir / "none");
  const RunResult second = matbake({"build", (lib.dir / "b.toml").string()});
  EXPECT_EQ(second.exit_code, 1);
  expect_one_error_line(second, (lib.dir / "b.toml").string(), "its output folder " + lib.out.string() + " belongs to " +
                                                                   lib.manifest.string());
  EXPECT_EQ(files_outside(lib.dir.path(), lib.dir / "none"), before);
  EXPECT_EQ(matbake({"build", (lib.dir / "b.toml").string(), "-n"}).exit_code, 1);
  EXPECT_NE(lib.build().out.find("nothing to do"), std::string::npos);

  // Shared: each builds and stays up to date after the other; dropping a material removes only its files.
  fs::remove_all(lib.out);
  for (const fs::path& m : {lib.manifest, lib.dir / "b.toml"}) write_bytes(m, "shared_output = true\n" + read_bytes(m));
  ASSERT_EQ(lib.build().exit_code, 0);
  ASSERT_EQ(matbake({"build", (lib.dir / "b.toml").string()}).exit_code, 0);
  EXPECT_NE(lib.build().out.find("nothing to do"), std::string::npos);
  EXPECT_NE(matbake({"build", (lib.dir / "b.toml").string()}).out.find("nothing to do"), std::string::npos);
  std::string text = read_bytes(lib.dir / "b.toml");
  text.replace(text.find("[materials.b0]"), 14, "[materials.b1]");
  write_bytes(lib.dir / "b.toml", text);
  const RunResult renamed = matbake({"build", (lib.dir / "b.toml").string()});
  EXPECT_EQ(renamed.exit_code, 0) << renamed.err;
  EXPECT_FALSE(fs::exists(lib.out / "materials/b0_orm.png"));
  EXPECT_TRUE(fs::exists(lib.out / "materials/b1_orm.png"));
  EXPECT_TRUE(fs::exists(lib.out / "materials/m0_orm.png"));
  EXPECT_NE(lib.build().out.find("nothing to do"), std::string::npos);
}

// A run that would remove more than half of what the build made (a renamed folder, a lost input)
// keeps the files and says why, exit 1; --prune removes them.
TEST(Gate, RemovingMostOutputsAtOnceNeedsPrune) {
  Library lib;
  std::string manifest = "output = \"out\"\n";
  for (int m = 0; m < 4; ++m) {
    manifest += "[materials.m" + std::to_string(m) + "]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n"
                "layout = \"gltf-orm\"\n";
  }
  write_bytes(lib.manifest, manifest);
  ASSERT_EQ(lib.build().exit_code, 0);
  write_bytes(lib.manifest, "output = \"out\"\n[materials.m0]\nsources = { base_color = \"kd.png\", metallic = 0.0, roughness = 0.5 }\n"
                            "layout = \"gltf-orm\"\n");
  const RunResult held = lib.build();
  EXPECT_EQ(held.exit_code, 1);
  EXPECT_NE(held.err.find("this run would remove 12 of the 16 files the build made"), std::string::npos) << held.err;
  EXPECT_TRUE(fs::exists(lib.out / "materials/m3_orm.png"));
  const RunResult pruned = lib.build({"--prune"});
  EXPECT_EQ(pruned.exit_code, 0) << pruned.err;
  EXPECT_FALSE(fs::exists(lib.out / "materials/m3_orm.png"));
  EXPECT_TRUE(fs::exists(lib.out / "materials/m0_orm.png"));
}

}  // namespace
}  // namespace matbake::test
