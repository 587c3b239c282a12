// The README's and docs/'s examples are what a new user copies first: every ```toml block is
// valid TOML and every ```json block valid JSON (docs/build.md's rule example was an inline table
// over several lines, which TOML forbids), every relative link resolves, and every matbake command
// of a ```sh block runs (exit 0) in a folder holding the files it names.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "matbake/ktx2.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

struct Block {
  std::string language;
  std::string text;
  int line = 0;  // of the opening fence
};

std::vector<fs::path> markdown_files() {
  const fs::path root(MATBAKE_SOURCE_DIR);
  std::vector<fs::path> files = {root / "README.md", root / "CONTRIBUTING.md"};
  for (const auto& entry : fs::directory_iterator(root / "docs")) {
    if (entry.path().extension() == ".md") files.push_back(entry.path());
  }
  return files;
}

std::vector<Block> fenced_blocks(const fs::path& file) {
  std::ifstream in(file);
  std::vector<Block> blocks;
  std::string line;
  std::optional<Block> open;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.rfind("```", 0) == 0) {
      if (open) {
        blocks.push_back(*open);
        open.reset();
      } else {
        open = Block{line.substr(3), "", number};
      }
    } else if (open) {
      open->text += line + "\n";
    }
  }
  return blocks;
}

TEST(DocsExamples, EveryTomlAndJsonBlockParses) {
  int toml_blocks = 0, json_blocks = 0;
  for (const fs::path& file : markdown_files()) {
    for (const Block& block : fenced_blocks(file)) {
      const std::string where = file.filename().string() + ":" + std::to_string(block.line);
      if (block.language == "toml") {
        ++toml_blocks;
        try {
          const toml::table parsed = toml::parse(block.text);
          EXPECT_FALSE(parsed.empty()) << where;
        } catch (const toml::parse_error& e) {
          ADD_FAILURE() << where << ": not valid TOML: " << e.description() << " at line "
                        << e.source().begin.line << " of the block";
        }
      } else if (block.language == "json") {
        ++json_blocks;
        EXPECT_FALSE(nlohmann::json::parse(block.text, nullptr, false).is_discarded()) << where << ": not valid JSON";
      }
    }
  }
  EXPECT_GE(toml_blocks, 1);
  EXPECT_GE(json_blocks, 1);
}

// A TOML block with materials or scenes is a manifest (docs/build.md's schema): it loads and plans,
// every key and value known, in a folder where only the files it names are missing (a rule's
// match finds one texture); `build -n` then fails for those files alone.
TEST(DocsExamples, EveryManifestBlockLoads) {
  int manifests = 0;
  for (const fs::path& file : markdown_files()) {
    for (const Block& block : fenced_blocks(file)) {
      if (block.language != "toml" || (block.text.find("[materials.") == std::string::npos &&
                                       block.text.find("[scenes.") == std::string::npos)) {
        continue;
      }
      ++manifests;
      TempDir dir;
      fs::create_directories(dir / "textures");
      write_raw(dir / "textures/brick_BaseColor.png", 4, 4, 3, "uint8", std::vector<double>(48, 120));
      write_bytes(dir / "m.toml", block.text);
      const RunResult r = matbake({"build", (dir / "m.toml").string(), "-n"});
      const std::string where = file.filename().string() + ":" + std::to_string(block.line);
      EXPECT_NE(r.out.find("jobs would be built"), std::string::npos) << where << ": did not load\n" << r.err;
      std::istringstream errors(r.err);
      for (std::string line; std::getline(errors, line);) {
        const bool missing = line.find("no such file") != std::string::npos || line.find("cannot read the glTF") != std::string::npos ||
                             line.find("jobs failed") != std::string::npos;
        EXPECT_TRUE(missing) << where << ": " << line;
      }
    }
  }
  EXPECT_GE(manifests, 1);
}

// The anchors GitHub gives a Markdown file's headings (outside code blocks): the heading's text in
// lower case, every character but letters, digits, '-', '_' and spaces dropped (non-ASCII kept, as
// the letters they mostly are here), spaces made '-'; a repeated anchor gets -1, -2, ...
std::set<std::string> heading_anchors(const fs::path& file) {
  std::ifstream in(file);
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  bool code = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("```", 0) == 0) code = !code;
    if (code || line.empty() || line[0] != '#') continue;
    const std::size_t text = line.find_first_not_of('#');
    if (text == std::string::npos || line[text] != ' ') continue;
    std::string anchor;
    for (char c : line.substr(text + 1)) {
      const auto u = static_cast<unsigned char>(c);
      if (std::isalnum(u) || c == '-' || c == '_' || u >= 0x80) anchor += char(std::tolower(u));
      else if (c == ' ') anchor += '-';
    }
    const int repeat = seen[anchor]++;
    anchors.insert(repeat == 0 ? anchor : anchor + "-" + std::to_string(repeat));
  }
  return anchors;
}

// Links such as [build](build.md), [x](../README.md#anchor) or [y](#anchor): the file they name
// exists, and so does the heading an anchor names in a Markdown file.
TEST(DocsExamples, EveryRelativeLinkResolves) {
  int anchors = 0;
  for (const fs::path& file : markdown_files()) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string s = text.str();
    for (std::size_t at = s.find("]("); at != std::string::npos; at = s.find("](", at + 2)) {
      const std::size_t end = s.find(')', at + 2);
      if (end == std::string::npos) break;
      const std::string target = s.substr(at + 2, end - at - 2);
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0 || target.empty()) continue;
      const std::size_t hash = target.find('#');
      const fs::path named = hash == 0 ? file : file.parent_path() / target.substr(0, hash);
      EXPECT_TRUE(fs::exists(named)) << file.filename().string() << " links to " << target;
      if (hash == std::string::npos || named.extension() != ".md" || !fs::exists(named)) continue;
      ++anchors;
      EXPECT_TRUE(heading_anchors(named).contains(target.substr(hash + 1)))
          << file.filename().string() << " links to " << target << ", a heading " << named.filename().string() << " does not have";
    }
  }
  EXPECT_GT(anchors, 0);  // the check ran
}

// The README is a landing page: the two commands first (README command 1 and 2, the same words
// CI's .ci/run and the scripts' comments use), at most 150 lines; details live in docs/.
TEST(DocsExamples, TheReadmeIsALandingPageThatOpensWithTheTwoCommands) {
  const fs::path readme = fs::path(MATBAKE_SOURCE_DIR) / "README.md";
  std::ifstream in(readme);
  int lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  EXPECT_LE(lines, 150);
  const std::vector<Block> blocks = fenced_blocks(readme);
  ASSERT_FALSE(blocks.empty());
  EXPECT_EQ(blocks[0].language, "sh");
  std::istringstream commands(blocks[0].text);
  std::vector<std::string> words;
  for (std::string line; std::getline(commands, line);) {
    line.resize(line.find(" #") == std::string::npos ? line.size() : line.find(" #"));
    words.push_back(line.substr(0, line.find_last_not_of(' ') + 1));
  }
  const std::vector<std::string> expected = {"bash scripts/example.sh", "bash scripts/test.sh"};
  EXPECT_EQ(words, expected);
}

// The examples' scene.gltf: three quads on a floor, materials Brick, Steel and Rubber, each quad's
// UVs over a 0.1 × 0.1 corner, so that an AO texture of 1024² bakes 10⁴ texels, not 10⁶.
void write_small_scene(const fs::path& file) {
  GltfBuilder b;
  const int positions = b.add_vec3({-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1});
  const int normals = b.add_vec3({0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0});
  const int uvs = b.add_floats({0, 0, 0.1f, 0, 0.1f, 0.1f, 0, 0.1f}, "VEC2", 2);
  const int indices = b.add_indices({0, 2, 1, 0, 3, 2});
  std::vector<int> nodes;
  for (const char* name : {"Brick", "Steel", "Rubber"}) {
    const int mesh = b.add_mesh(positions, indices, 4, normals);
    const int material = int(b.doc["materials"].size());
    b.doc["materials"].push_back({{"name", name}, {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}});
    b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["attributes"]["TEXCOORD_0"] = uvs;
    b.doc["meshes"][std::size_t(mesh)]["primitives"][0]["material"] = material;
    nodes.push_back(b.add_node({{"mesh", mesh}, {"translation", {0.0, 0.5 * double(nodes.size()), 0.0}}}));
  }
  b.write(file, nodes);
}

// The files the examples name, small: 8×8 images (a Schüler pair A/B and brick_a/brick_b of a
// plausible dielectric), the example as assets.toml and as examples/, its scene as scene.gltf
// (a material renamed Brick) and scene.glb (and as low.glb, high.glb and cage.glb), the presets.
void write_example_files(const fs::path& dir) {
  const auto image = [&](const char* name, int channels, double value) {
    write_raw(dir / name, 8, 8, channels, "uint8", std::vector<double>(std::size_t(64 * channels), value));
  };
  for (const char* f : {"albedo.png", "base.png", "a.png"}) image(f, 3, 140);
  for (const char* f : {"gloss.png", "m.png", "r.png", "ao.png"}) image(f, 1, 150);
  image("mr.png", 3, 120);
  for (const char* f : {"A.png", "brick_a.png"}) image(f, 4, 140);
  std::vector<double> pair_b;
  for (int i = 0; i < 64; ++i) pair_b.insert(pair_b.end(), {57, 57, 57, 160});  // F0 0.04, gloss 0.63
  for (const char* f : {"B.png", "brick_b.png"}) write_raw(dir / f, 8, 8, 4, "uint8", pair_b);
  write_raw(dir / "lin.exr", 8, 8, 3, "float", std::vector<double>(192, 0.25));
  copy_example(dir, true);  // the AO of few samples: the commands run, not the bake's quality
  fs::copy_file(dir / "showroom.toml", dir / "assets.toml");
  fs::create_directories(dir / "examples");
  copy_example(dir / "examples", true);
  write_small_scene(dir / "scene.gltf");
  fs::create_directory_symlink(fs::path(MATBAKE_SOURCE_DIR) / "presets", dir / "presets");
  ASSERT_EQ(matbake({"export", (dir / "scene.gltf").string(), "-o", (dir / "scene.glb").string()}).exit_code, 0);
  // bake's pair: the scene onto itself (the commands run; bake.md has its closed forms).
  fs::copy_file(dir / "scene.glb", dir / "low.glb");
  fs::copy_file(dir / "scene.glb", dir / "high.glb");
  fs::copy_file(dir / "scene.glb", dir / "cage.glb");  // the low-poly itself: a cage that touches it
  // texture.ktx2: UASTC 4×4, one level (inspect reads it; no encoder needed).
  const auto ktx2_file = ktx2::write_uastc({.width = 4, .height = 4, .levels = {*ktx2::uastc_level(std::vector<unsigned char>(16), 0)}});
  ASSERT_TRUE(ktx2_file);
  write_bytes(dir / "texture.ktx2", std::string(ktx2_file->begin(), ktx2_file->end()));
}

// A shell line's commands (split at &&), comments cut.
std::vector<std::string> commands_of(std::string line) {
  if (const std::size_t hash = line.find(" #"); hash != std::string::npos) line.resize(hash);
  if (line.rfind('#', 0) == 0) return {};
  std::vector<std::string> commands;
  for (std::size_t at = 0;;) {
    const std::size_t next = line.find("&&", at);
    std::string c = line.substr(at, next == std::string::npos ? std::string::npos : next - at);
    c.erase(0, c.find_first_not_of(' '));
    c.erase(c.find_last_not_of(' ') + 1);
    if (!c.empty()) commands.push_back(c);
    if (next == std::string::npos) return commands;
    at = next + 2;
  }
}

// Each file's commands in order, in a folder of its own: matbake's, and ninja's after a plan; a
// line with anything else (the set-up scripts, cmake, Slurm's submit) is not run. KTX2 lines need
// basisu (skipped, said, without it).
TEST(DocsExamples, EveryMatbakeCommandRuns) {
#ifdef MATBAKE_SANITIZED
  GTEST_SKIP() << "the docs' commands run in the release build (each command has its own tests under the sanitizers)";
#endif
  const std::vector<std::string> env = matbake_environment();
  const bool has_basisu = std::any_of(env.begin(), env.end(), [](const std::string& e) { return e.rfind("MATBAKE_BASISU=", 0) == 0; }) ||
                          std::getenv("MATBAKE_BASISU");
  const std::string path = "PATH=" + fs::path(matbake_exe()).parent_path().string() + ":" + std::getenv("PATH");
  int ran = 0, not_run = 0;
  for (const fs::path& file : markdown_files()) {
    TempDir dir;
    bool files_written = false;
    for (const Block& block : fenced_blocks(file)) {
      if (block.language != "sh") continue;
      std::istringstream lines(block.text);
      std::string line;
      for (int n = 1; std::getline(lines, line); ++n) {
        const std::vector<std::string> commands = commands_of(line);
        const bool runnable = !commands.empty() && std::all_of(commands.begin(), commands.end(), [](const std::string& c) {
          return c.rfind("matbake ", 0) == 0 || c == "ninja";
        });
        if (!runnable || (!has_basisu && line.find("ktx2") != std::string::npos)) {
          not_run += !commands.empty();
          continue;
        }
        if (!files_written) {
          write_example_files(dir.path());
          files_written = true;
        }
        const auto start = std::chrono::steady_clock::now();
        const RunResult r = run("/bin/bash", {"-c", "cd \"$0\" && " + line.substr(0, line.find(" #")), dir.path().string()},
                                [&] { auto e = env; e.push_back(path); return e; }());
        EXPECT_EQ(r.exit_code, 0) << file.filename().string() << ":" << block.line + n << ": " << line << "\n" << r.err;
        ++ran;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (seconds > 5) std::printf("  %.0f s: %s\n", seconds, line.c_str());
      }
    }
  }
  std::printf("  %d commands ran, %d lines not run (set-up scripts, cmake, sbatch%s)\n", ran, not_run,
              has_basisu ? "" : ", KTX2 without basisu");
  EXPECT_GE(ran, 40);
}

}  // namespace
}  // namespace matbake::test
