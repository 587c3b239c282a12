// Issue "Hostile input": each finding as the CLI meets it. Every case: exit 1 (2 for usage), one
// line `matbake: error: <file>: <problem>`, nothing written, no temporary file left, inputs untouched.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <sys/stat.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <zlib.h>

#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/gltf_files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A PNG of `width` × `height` whose data is a few zero bytes (the header alone declares the size).
std::string png_declaring(std::uint32_t width, std::uint32_t height) {
  const auto be32 = [](std::uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  const auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    const auto crc = std::uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size())));
    return be32(std::uint32_t(data.size())) + body + be32(crc);
  };
  std::string zeros(10, '\0'), compressed(64, '\0');
  uLongf length = compressed.size();
  compress(reinterpret_cast<Bytef*>(compressed.data()), &length, reinterpret_cast<const Bytef*>(zeros.data()), zeros.size());
  compressed.resize(length);
  const std::string header = be32(width) + be32(height) + std::string{8, 2, 0, 0, 0};  // 8-bit RGB
  return "\x89PNG\r\n\x1a\n" + chunk("IHDR", header) + chunk("IDAT", compressed) + chunk("IEND", "");
}

constexpr int kFailed = 1, kUsage = 2;

// Runs matbake and checks the error contract; `watched` files must come out byte-identical and
// `folder` must hold exactly what it held before.
void expect_refused(const std::vector<std::string>& args, int exit_code, const std::string& path, const std::string& problem,
                    const fs::path& folder, const std::vector<fs::path>& watched = {}) {
  std::vector<std::string> before;
  for (const fs::path& f : watched) before.push_back(read_bytes(f));
  const std::vector<std::string> listing = list_folder(folder);
  const RunResult r = matbake(args);
  EXPECT_EQ(r.exit_code, exit_code) << r.err;
  expect_one_error_line(r, path, problem);
  EXPECT_EQ(list_folder(folder), listing) << args[0];
  for (std::size_t i = 0; i < watched.size(); ++i) EXPECT_EQ(read_bytes(watched[i]), before[i]) << watched[i];
}

TEST(Hostile, DeclaredSizesBeyondThePixelLimitAreRefusedBeforeAllocating) {
  TempDir dir;
  const fs::path huge = dir / "huge.png";
  write_bytes(huge, png_declaring(100000, 100000));
  const std::string problem = "100000x100000 is more than the limit of 268435456 pixels";
  const fs::path out = dir / "out";
  fs::create_directories(out);
  expect_refused({"validate", "--ks", huge.string()}, kFailed, huge.string(), problem, dir.path());
  expect_refused({"pack", "--kd", huge.string(), "--ks", "0.04", "--gloss", "0.5", "-o", (out / "s_{texture}.png").string()},
                 kFailed, huge.string(), problem, out);
  expect_refused({"workflow", "--kd", huge.string(), "--ks", "0.04", "--gloss", "0.5", "--to", "gltf-orm", "-o",
                  (out / "w_{texture}.png").string()},
                 kFailed, huge.string(), problem, out);
  expect_refused({"unpack", huge.string(), huge.string(), "-o", out.string()}, kFailed, huge.string(), problem, out);
  expect_refused({"convert", huge.string(), "-o", (out / "c.exr").string()}, kFailed, huge.string(), problem, out);
  // Made, not read: a constant-only pack of that size.
  expect_refused({"pack", "--kd", "0.5", "--ks", "0.04", "--gloss", "0.5", "--size", "100000x100000", "-o",
                  (out / "b_{texture}.png").string()},
                 kFailed, "", problem, out);

  // --max-pixels moves the limit both ways; a raised one still reads rows as they come, so a
  // 20000×20000 header over 10 bytes fails at its first missing row, not after allocating 4.8 GB.
  const fs::path big = dir / "big.png";
  write_bytes(big, png_declaring(20000, 20000));
  expect_refused({"--max-pixels", "1000000000", "validate", "--ks", big.string()}, kFailed, big.string(), "cannot read pixels", dir.path());
  write_raw(dir / "small.png", 4, 4, 3, "uint8", std::vector<double>(48, 56));  // F0 0.04: passes
  expect_refused({"--max-pixels", "15", "validate", "--ks", (dir / "small.png").string()}, kFailed, (dir / "small.png").string(),
                 "4x4 is more than the limit of 15 pixels", dir.path());
  EXPECT_EQ(matbake({"--max-pixels", "16", "-q", "validate", "--ks", (dir / "small.png").string()}).exit_code, 0);
}

// Found by fuzzing: a 296-byte EXR declaring a 2 GB attribute (2.2 GB and 7.5 s before), and a
// PNG whose damaged ICC profile made OIIO 2.4 read out of bounds (exit 139 before), in the
// commands that read images, with any extension.
TEST(Hostile, ExrHeaderSizesAndDamagedIccProfilesAreErrors) {
  TempDir dir;
  const fs::path regressions = fs::path(MATBAKE_SOURCE_DIR) / "tests/fuzz/regressions/image";
  const fs::path exr = dir / "texture.png", icc = dir / "icc.png";
  fs::copy_file(regressions / "exr-attribute-declares-2GB.exr", exr);
  fs::copy_file(regressions / "png-damaged-icc-profile.png", icc);
  const fs::path out = dir / "out";
  fs::create_directories(out);
  const std::string too_long = "not a readable image: OpenEXR header: Attribute 'owner', type 'string': Invalid size 2147483392";
  expect_refused({"convert", exr.string(), "-o", (out / "c.exr").string()}, kFailed, exr.string(), too_long, out, {exr});
  expect_refused({"validate", "--ks", exr.string()}, kFailed, exr.string(), too_long, out, {exr});
  expect_refused({"convert", icc.string(), "-o", (out / "c.exr").string()}, kFailed, icc.string(), "cannot read pixels", out, {icc});
  expect_refused({"pack", "--kd", icc.string(), "--ks", "0.04", "--gloss", "0.5", "-o", (out / "p_{texture}.png").string()},
                 kFailed, icc.string(), "cannot read pixels", out, {icc});
}

// A tiled, mip-mapped EXR (as maketx writes textures): its level 0 is read, texel for texel.
TEST(Hostile, TiledMipMappedExrIsReadAtLevelZero) {
  TempDir dir;
  const int width = 37, height = 23;  // not a multiple of the 16-pixel tiles
  OIIO::ImageBuf source(OIIO::ImageSpec(width, height, 4, OIIO::TypeDesc::FLOAT));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float v[4] = {float(x) / width, float(y) / height, 0.25f, 1.0f};
      source.setpixel(x, y, v);
    }
  }
  OIIO::ImageSpec config;
  config.tile_width = config.tile_height = 16;
  config.attribute("maketx:filtername", "box");
  ASSERT_TRUE(OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, source, (dir / "tiled.exr").string(), config));
  OIIO::ImageBuf check((dir / "tiled.exr").string());
  ASSERT_GT(check.nmiplevels(), 1);
  ASSERT_EQ(check.spec().tile_width, 16);

  const RunResult r = matbake({"convert", (dir / "tiled.exr").string(), "--from", "linear", "-o", (dir / "flat.exr").string(),
                               "--bits", "float"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const RawImage flat = read_raw(dir / "flat.exr");
  ASSERT_EQ(flat.width, width);
  ASSERT_EQ(flat.height, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = (std::size_t(y) * width + std::size_t(x)) * 4;
      ASSERT_NEAR(flat.samples[i], double(x) / width, 1e-3) << x << "," << y;  // half in the texture
      ASSERT_NEAR(flat.samples[i + 1], double(y) / height, 1e-3) << x << "," << y;
    }
  }
  const int validated = matbake({"-q", "validate", "--ks", (dir / "tiled.exr").string()}).exit_code;
  EXPECT_TRUE(validated == 0 || validated == 3) << validated;  // clean or flagged: read, not crashed
}

// The glTF findings: a huge accessor count, an image URI naming the folder, files that are links
// leaving the asset's folder.
TEST(Hostile, GltfCountsFoldersAndLinks) {
  TempDir dir;
  const std::vector<float> triangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  fs::create_directories(dir / "out");
  const std::string out = (dir / "out" / "x.glb").string();
  {
    GltfBuilder b;
    b.add_node({{"mesh", b.add_mesh(b.add_vec3(triangle))}});
    b.doc["accessors"][0]["count"] = std::uint64_t{1} << 62;
    b.write(dir / "count.gltf", {0});
    const std::string file = (dir / "count.gltf").string();
    expect_refused({"bake-ao", file, "-o", out}, kFailed, file, "accessor 0 reaches beyond its buffer", dir / "out");
    expect_refused({"export", file, "-o", out, "--ao-samples", "4"}, kFailed, file, "accessor 0 reaches beyond its buffer", dir / "out");
  }
  {
    GltfBuilder b;
    b.add_node({{"mesh", b.add_mesh(b.add_vec3(triangle))}});
    b.doc["images"] = {{{"uri", "."}}};
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    b.doc["meshes"][0]["primitives"][0]["material"] = 0;
    b.doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = b.add_floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
    b.write(dir / "dot.gltf", {0});
    const std::string file = (dir / "dot.gltf").string();
    expect_refused({"export", file, "-o", out}, kFailed, file, "image 0: '.' cannot be read", dir / "out");
  }
  {
    // The buffer is a link beside the glTF to a file elsewhere: judged by its real path.
    fs::create_directories(dir / "asset");
    fs::create_directories(dir / "elsewhere");
    GltfBuilder b;
    b.external_bin = true;
    b.add_node({{"mesh", b.add_mesh(b.add_vec3(triangle))}});
    b.write(dir / "elsewhere" / "scene.gltf", {0});
    const json written = json::parse(read_bytes(dir / "elsewhere" / "scene.gltf"));
    const std::string bin = written["buffers"][0]["uri"];
    fs::copy_file(dir / "elsewhere" / "scene.gltf", dir / "asset" / "scene.gltf");
    fs::create_symlink(dir / "elsewhere" / bin, dir / "asset" / bin);
    const std::string file = (dir / "asset" / "scene.gltf").string();
    const std::string problem = "'" + bin + "' is a link to a file outside the glTF's folder";
    expect_refused({"export", file, "-o", out}, kFailed, file, problem, dir / "out");
    expect_refused({"bake-ao", file, "-o", out}, kFailed, file, problem, dir / "out");
    // A link that stays inside the folder is an ordinary file.
    fs::remove(dir / "asset" / bin);
    fs::copy_file(dir / "elsewhere" / bin, dir / "asset" / "real.bin");
    fs::create_symlink("real.bin", dir / "asset" / bin);
    const RunResult r = matbake({"-q", "export", file, "-o", out});
    EXPECT_EQ(r.exit_code, 0) << r.err;
  }
}

// Every output option, not only -o, refuses an input as its target (links included), and two
// outputs of one run may not be one file.
TEST(Hostile, EveryOutputOptionRefusesAnInput) {
  TempDir dir;
  write_raw(dir / "a.png", 2, 2, 4, "uint8", {200, 100, 50, 255, 10, 20, 30, 255, 90, 90, 90, 255, 1, 2, 3, 255});
  write_raw(dir / "b.png", 2, 2, 4, "uint8", {10, 10, 10, 128, 250, 200, 40, 255, 11, 11, 11, 0, 60, 60, 60, 200});
  fs::create_symlink(dir / "b.png", dir / "link-to-b.png");
  const std::string a = (dir / "a.png").string(), b = (dir / "b.png").string(), link = (dir / "link-to-b.png").string();
  const std::vector<fs::path> inputs = {dir / "a.png", dir / "b.png"};
  const std::string is_input = "is an input; matbake never overwrites its inputs";
  fs::create_directories(dir / "out");
  const std::string out = (dir / "out").string();

  expect_refused({"validate", "--from", "schuler", a, b, "--heatmap", b}, kUsage, b, is_input, dir.path(), inputs);
  expect_refused({"validate", "--from", "schuler", a, b, "--heatmap", link}, kUsage, link, is_input, dir.path(), inputs);
  expect_refused({"validate", "--from", "schuler", a, b, "--report", a}, kUsage, a, is_input, dir.path(), inputs);
  expect_refused({"validate", "--from", "schuler", a, b, "--heatmap", out + "/h.png", "--report", out + "/h.png"}, kUsage,
                 out + "/h.png", "is written twice (heatmap and report)", dir.path(), inputs);
  expect_refused({"workflow", "--from", "schuler", a, b, "--to", "gltf-orm", "-o", out + "/w_{texture}.png", "--report", a},
                 kUsage, a, is_input, dir / "out", inputs);
  expect_refused({"workflow", "--from", "schuler", a, b, "--to", "gltf-orm", "-o", out + "/w_{texture}.png", "--report",
                  out + "/w_orm.png"},
                 kUsage, out + "/w_orm.png", "is written twice (texture orm and report)", dir / "out", inputs);
  // unpack writes <folder>/kd.png, ... : inputs named so are refused before any map is written.
  fs::create_directories(dir / "u");
  fs::copy_file(dir / "a.png", dir / "u" / "kd.png");
  fs::copy_file(dir / "b.png", dir / "u" / "ks.png");
  expect_refused({"unpack", (dir / "u" / "kd.png").string(), (dir / "u" / "ks.png").string(), "-o", (dir / "u").string()},
                 kUsage, (dir / "u" / "kd.png").string(), is_input, dir / "u", {dir / "u" / "kd.png", dir / "u" / "ks.png"});

  GltfBuilder scene;
  scene.external_bin = true;
  scene.add_node({{"mesh", scene.add_mesh(scene.add_vec3({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
  scene.write(dir / "scene.gltf", {0});
  const std::string gltf = (dir / "scene.gltf").string();
  const std::string bin = (dir / json::parse(read_bytes(dir / "scene.gltf"))["buffers"][0]["uri"].get<std::string>()).string();
  const std::vector<fs::path> scene_files = {dir / "scene.gltf", bin};
  expect_refused({"export", gltf, "-o", out + "/x.glb", "--report", gltf}, kUsage, gltf, is_input, dir / "out", scene_files);
  expect_refused({"export", gltf, "-o", out + "/x.glb", "--report", bin}, kUsage, bin, is_input, dir / "out", scene_files);
  expect_refused({"export", gltf, "-o", out + "/x.glb", "--report", out + "/x.glb"}, kUsage, out + "/x.glb",
                 "is written twice (glTF output and report)", dir / "out", scene_files);
  expect_refused({"bake-ao", gltf, "--dump", bin}, kUsage, bin, is_input, dir / "out", scene_files);
}

// Sources that never end (a FIFO, /dev/zero) are refused, not read: only regular files are images.
TEST(Hostile, SourcesMustBeRegularFiles) {
  TempDir dir;
  ASSERT_EQ(mkfifo((dir / "fifo.png").c_str(), 0600), 0);
  for (const std::string& source : {std::string("fifo.png"), std::string("/dev/zero")}) {
    write_bytes(dir / "m.toml", "output = \"out\"\n[materials.a]\nsources = { kd = \"" + source +
                                    "\", ks = 0.04, gloss = 0.5 }\nlayout = \"schuler\"\n");
    const RunResult r = matbake({"build", (dir / "m.toml").string()});
    EXPECT_EQ(r.exit_code, 1) << r.err;
    const std::string path = source[0] == '/' ? source : (dir / source).string();
    EXPECT_NE(r.err.find("matbake: error: " + (dir / "m.toml").string() + ":3:18: materials.a.sources.kd: " + path +
                         ": is not a regular file (material:a)"),
              std::string::npos)
        << r.err;
  }
  const RunResult direct = matbake({"validate", "--ks", "/dev/zero"});
  EXPECT_EQ(direct.exit_code, 1);
  expect_one_error_line(direct, "/dev/zero", "is not a regular file");
}

// build writes nowhere but inside the output folder's real path: a link inside it to another
// folder (out/materials, out/.matbake) is refused, and nothing lands where it points.
TEST(Hostile, BuildDoesNotWriteThroughLinksInTheOutputFolder) {
  TempDir dir;
  fs::create_directories(dir / "out");
  fs::create_directories(dir / "elsewhere");
  const std::string manifest = (dir / "m.toml").string();
  write_bytes(manifest, "output = \"out\"\n[materials.a]\nsources = { kd = 0.5, ks = 0.04, gloss = 0.5 }\nlayout = \"schuler\"\n");
  fs::create_directory_symlink(dir / "elsewhere", dir / "out" / "materials");
  const RunResult r = matbake({"build", manifest});
  EXPECT_EQ(r.exit_code, 1);
  expect_one_error_line(r, (dir / "out" / "materials" / "a_a.png").string(), "material:a would be written outside the output folder");
  fs::remove(dir / "out" / "materials");
  fs::create_directory_symlink(dir / "elsewhere", dir / "out" / ".matbake");
  const RunResult state = matbake({"build", manifest});
  EXPECT_EQ(state.exit_code, 1);
  expect_one_error_line(state, (dir / "out" / ".matbake").string(), "is a link out of the output folder");
  EXPECT_TRUE(list_folder(dir / "elsewhere").empty());
  // The output folder itself may be a link: its real path is where everything goes.
  fs::remove(dir / "out" / ".matbake");
  fs::remove(dir / "out");
  fs::create_directory_symlink(dir / "elsewhere", dir / "out");
  const RunResult linked = matbake({"-q", "build", manifest});
  EXPECT_EQ(linked.exit_code, 0) << linked.err;
  EXPECT_TRUE(fs::exists(dir / "elsewhere" / "materials" / "a_a.png"));
}

// An output that is an input under another name — a hard link, or a link to a source that lives in
// the output folder — is refused before anything runs, the source's bytes untouched.
TEST(Hostile, AnOutputThatIsAnInputUnderAnotherNameIsRefused) {
  for (const bool hard : {true, false}) {
    SCOPED_TRACE(hard ? "hard link" : "symbolic link");
    TempDir dir;
    fs::create_directories(dir / "out" / "materials");
    const fs::path source = dir / "out" / "kd.png";
    write_raw(source, 4, 4, 3, "uint8", std::vector<double>(48, 120));
    const std::string before = read_bytes(source);
    const std::string manifest = (dir / "m.toml").string();
    write_bytes(manifest, "[materials.a]\nsources = { kd = \"out/kd.png\", ks = 0.04, gloss = 0.5 }\nlayout = \"gltf-orm\"\n");
    const fs::path output = dir / "out" / "materials" / "a_base_color.png";
    if (hard) {
      fs::create_hard_link(source, output);
    } else {
      fs::create_symlink(source, output);
    }
    const RunResult r = matbake({"build", manifest});
    EXPECT_EQ(r.exit_code, 1);
    expect_one_error_line(r, output.string(), "material:a would overwrite an input; matbake never does");
    EXPECT_EQ(read_bytes(source), before);
  }
}

}  // namespace
}  // namespace matbake::test
