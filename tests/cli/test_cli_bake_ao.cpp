// `matbake bake-ao` end to end: a wall on a floor through the CLI, byte-identical dumps across
// thread counts, and bad scenes refused with nothing written.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/gltf_validator.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

// A 2000-unit floor as a fan around the origin (vertex 0), and a wall just behind x = 0 facing +x.
void write_wall_scene(const fs::path& path) {
  GltfBuilder b;
  const float h = 1000, gap = 1e-3f;
  const int floor = b.add_mesh(b.add_vec3({0, 0, 0, -h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0}),
                               b.add_indices({0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1}));
  const int wall = b.add_mesh(b.add_vec3({-gap, -h, 0, -gap, h, 0, -gap, h, 2 * h, -gap, -h, 2 * h}),
                              b.add_indices({0, 1, 2, 0, 2, 3}));
  b.write(path, {b.add_node({{"mesh", floor}}), b.add_node({{"mesh", wall}})});
}

TEST(CliBakeAo, FootOfAWallAndDeterministicDumps) {
  TempDir dir;
  write_wall_scene(dir / "wall.gltf");
  const auto r = matbake({"--json", "bake-ao", (dir / "wall.gltf").string(), "--dump", (dir / "ao.csv").string(),
                          "--samples", "2048", "--falloff", "none", "--max-distance", "1e5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["vertices"], 9);
  std::ifstream csv(dir / "ao.csv");
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(header, "node,mesh,primitive,vertex,x,y,z,ao");
  const double ao = std::stod(first.substr(first.rfind(',') + 1));
  EXPECT_NEAR(ao, 0.5, 3 * std::sqrt(0.25 / 2048));  // 3σ of the binary estimator
  for (const char* jobs : {"1", "2"}) {
    const auto run = matbake({"-q", "--jobs", jobs, "bake-ao", (dir / "wall.gltf").string(), "--dump",
                              (dir / (std::string("ao") + jobs + ".bin")).string(), "--seed", "3"});
    ASSERT_EQ(run.exit_code, 0) << run.err;
  }
  EXPECT_EQ(read_bytes(dir / "ao1.bin"), read_bytes(dir / "ao2.bin"));
  EXPECT_EQ(read_bytes(dir / "ao1.bin").size(), 9 * sizeof(float));
}

// The written scene passes the Khronos glTF-Validator with no error and no warning, in both
// containers and both attributes, and the input is left as it was.
TEST(CliBakeAo, WrittenScenesAreValidatorClean) {
  TempDir dir;
  write_wall_scene(dir / "wall.gltf");
  const std::string input = read_bytes(dir / "wall.gltf");
  for (const char* into : {"COLOR_0", "_AO"}) {
    for (const char* ext : {".gltf", ".glb"}) {
      const fs::path out = dir / (std::string("wall") + into + ext);
      const auto r = matbake({"-q", "bake-ao", (dir / "wall.gltf").string(), "-o", out.string(), "--into", into,
                              "--samples", "64"});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      MATBAKE_VALIDATE_OR_SKIP(report, out);
      EXPECT_EQ(report->errors, 0) << report->summary;
      EXPECT_EQ(report->warnings, 0) << report->summary;
    }
  }
  EXPECT_EQ(read_bytes(dir / "wall.gltf"), input);
}

TEST(CliBakeAo, BadScenesAndUsage) {
  TempDir dir;
  write_wall_scene(dir / "good.gltf");
  std::ofstream(dir / "broken.gltf") << "{\"asset\": ";
  {
    nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / "good.gltf"));
    doc["buffers"][0]["uri"] = "../../etc/passwd";
    std::ofstream(dir / "escape.gltf") << doc.dump();
  }
  const std::string dump = (dir / "out.csv").string();
  for (const auto& [file, problem] :
       {std::pair{(dir / "broken.gltf").string(), "not a valid glTF"},
        std::pair{(dir / "escape.gltf").string(), "URI '../../etc/passwd' is outside the glTF's folder"},
        std::pair{(dir / "missing.gltf").string(), "no such file"}}) {
    const auto r = matbake({"bake-ao", file, "--dump", dump});
    EXPECT_EQ(r.exit_code, 1) << file;
    expect_one_error_line(r, file, problem);
  }
  const std::string good = (dir / "good.gltf").string();
  EXPECT_EQ(matbake({"bake-ao", good, "--dump", dump, "--samples", "0"}).exit_code, 2);
  EXPECT_EQ(matbake({"bake-ao", good, "--dump", dump, "--falloff", "cubic"}).exit_code, 2);
  EXPECT_EQ(matbake({"bake-ao", good, "--dump", (dir / "out.txt").string()}).exit_code, 2);
  EXPECT_FALSE(fs::exists(dump));
  const std::string before = read_bytes(dir / "good.gltf");
  using Case = std::pair<std::vector<std::string>, std::string>;
  for (const auto& [args, problem] :
       {Case{{"bake-ao", good}, "bake-ao writes a glTF, a dump or both"},
        Case{{"bake-ao", good, "-o", good}, good + ": is an input; matbake never overwrites its inputs"},
        Case{{"bake-ao", good, "-o", (dir / "out.obj").string()}, (dir / "out.obj").string() + ": the output is .gltf or .glb"},
        Case{{"bake-ao", good, "-o", (dir / "x.glb").string(), "--into", "COLOR_1"}, "--into 'COLOR_1' --existing-colors 'multiply': use COLOR_0 (with multiply or replace) or _AO"}}) {
    const auto r = matbake(args);
    EXPECT_EQ(r.exit_code, 2) << problem;
    expect_one_error_line(r, "", problem);
  }
  EXPECT_EQ(read_bytes(dir / "good.gltf"), before);
  EXPECT_EQ(list_folder(dir.path()), (std::vector<std::string>{"broken.gltf", "escape.gltf", "good.gltf"}));
}

}  // namespace
}  // namespace matbake::test
