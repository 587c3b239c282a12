// Slurm's memory requests against what the jobs hold: each job run as job.sh runs it (`--jobs 1
// build --only JOB`), its processes' resident memory summed as a cluster's cgroup counts them.
#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>

#include "support/basisu.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// Noise a PNG compresses poorly, as painted textures do: `channels` of side², 8-bit; a normal
// map's tilts stay within about 15° of the surface normal.
void write_painted_noise(const fs::path& file, int side, int channels, std::uint32_t seed, bool normal = false) {
  std::vector<double> samples(std::size_t(side) * std::size_t(side) * std::size_t(channels));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    seed = seed * 1664525u + 1013904223u;
    samples[i] = normal ? (i % 3 == 2 ? 250.0 : double(96 + (seed >> 24) % 64)) : double(40 + (seed >> 24) % 160);
  }
  write_raw(file, side, side, channels, "uint8", samples);
}

#ifdef MATBAKE_SANITIZED
#define SKIP_UNLESS_RELEASE() GTEST_SKIP() << "peaks are measured in the release build: AddressSanitizer's shadow memory is no job's"
#else
#define SKIP_UNLESS_RELEASE() static_cast<void>(0)
#endif

// Runs every job the plan submits and checks its peak against its request (a material's own, as
// `task_memory_mb` lists it; the array asks for the largest of them).
void expect_requests_cover_peaks(const fs::path& manifest) {
  const RunResult planned = matbake({"--json", "plan", manifest.string(), "--format", "slurm", "--dry-run", "-o", (manifest.parent_path() / "slurm").string()});
  ASSERT_EQ(planned.exit_code, 0) << planned.err;
  const json plan = json::parse(planned.out);
  std::vector<std::pair<std::string, std::int64_t>> requests;
  for (std::size_t i = 0; i < plan["array"]["jobs"].size(); ++i) {
    requests.emplace_back(plan["array"]["jobs"][i], plan["array"]["task_memory_mb"][i]);
  }
  for (const json& scene : plan["scenes"]) requests.emplace_back(scene["job"], scene["memory_mb"]);
  ASSERT_FALSE(requests.empty());
  for (const auto& [job, request] : requests) {
    const RunResult r = run_measured(matbake_exe(), {"--jobs", "1", "build", manifest.string(), "--only", job, "--force", "--quiet"},
                                     matbake_environment());
    ASSERT_EQ(r.exit_code, 0) << job << ": " << r.err;
    EXPECT_LE(r.peak_mb, double(request)) << job;
    std::printf("  %s: peak %.0f MB, request %lld MB\n", job.c_str(), r.peak_mb, static_cast<long long>(request));
  }
}

// memory_mb sets every job's request; material_memory_mb and scene_memory_mb their kind's, over it.
TEST(ClusterMemory, EachKindsSettingWinsOverEveryJobs) {
  TempDir dir;
  copy_example(dir.path());
  const std::string original = read_bytes(dir / "showroom.toml");
  const auto requests = [&](const std::string& cluster) {
    write_bytes(dir / "showroom.toml", original + "\n[cluster]\n" + cluster);
    const RunResult r = matbake({"--json", "plan", (dir / "showroom.toml").string(), "--format", "slurm", "--dry-run", "-o",
                                 (dir / "slurm").string()});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const json plan = json::parse(r.out);
    return std::pair{plan["array"]["memory_mb"].get<int>(), plan["scenes"][0]["memory_mb"].get<int>()};
  };
  EXPECT_EQ(requests("memory_mb = 1000\n"), std::pair(1000, 1000));
  EXPECT_EQ(requests("memory_mb = 1000\nmaterial_memory_mb = 2048\n"), std::pair(2048, 1000));
  EXPECT_EQ(requests("memory_mb = 1000\nscene_memory_mb = 8192\n"), std::pair(1000, 8192));
  EXPECT_EQ(requests("material_memory_mb = 3000\n").first, 3000);
}

TEST(ClusterMemory, RequestsCoverTheExamplesPeaks) {
  SKIP_UNLESS_RELEASE();
  TempDir dir;
  copy_example(dir.path(), true);
  expect_requests_cover_peaks(dir / "showroom.toml");
}

// A studio's library at 1024²: five and six maps (one file's channels picked), a spec-gloss material
// converted, and a scene using all three with AO textures, delivered as KTX2 when basisu is here.
TEST(ClusterMemory, RequestsCoverAFiveMapLibrarysPeaks) {
  SKIP_UNLESS_RELEASE();
  TempDir dir;
  constexpr int kSide = 1024;
  write_painted_noise(dir / "base.png", kSide, 3, 1);
  write_painted_noise(dir / "normal.png", kSide, 3, 2, true);
  write_painted_noise(dir / "emissive.png", kSide, 3, 3);
  write_painted_noise(dir / "metal.png", kSide, 1, 4);
  write_painted_noise(dir / "rough.png", kSide, 1, 5);
  write_painted_noise(dir / "orm.png", kSide, 3, 6);
  for (const char* f : {"showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  std::string why_not;
  const bool ktx2 = !basisu_for_tests(why_not).empty();
  if (!ktx2) std::printf("  the scene delivers PNG: %s\n", why_not.c_str());
  write_bytes(dir / "library.toml", std::string(R"(output = "out"
validate = { max_violations = 1.0 }
[materials.five]
sources = { base_color = "base.png", metallic = "metal.png", roughness = "rough.png", normal = "normal.png", emissive = "emissive.png" }
layout = "gltf-pbr"
[materials.six]
sources = { base_color = "base.png", occlusion = "orm.png:r", roughness = "orm.png:g", metallic = "orm.png:b", normal = "normal.png", emissive = "emissive.png" }
layout = "gltf-pbr"
[materials.spec_gloss]
sources = { kd = "base.png", ks = "emissive.png", gloss = "rough.png", normal = "normal.png" }
layout = "gltf-pbr"
[scenes.showroom]
input = "showroom.gltf"
materials = { painted_metal = "five", wood = "six", rubber = "spec_gloss" }
ao = { samples = 8, texture = 256 }
colour_max_size = 256
data_max_size = 256
normal_max_size = 256
texture_format = ")") + (ktx2 ? "ktx2" : "png") + "\"\n");
  expect_requests_cover_peaks(dir / "library.toml");
}

}  // namespace
}  // namespace matbake::test
