// `matbake convert` end to end: the built binary on generated inputs; exit codes, the one-line
// error format, outputs compared by value, and nothing left behind on failure.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <filesystem>

#include "support/expect_error.hpp"
#include "support/files.hpp"
#include "support/run.hpp"
#include "support/temp_dir.hpp"

namespace matbake::test {
namespace {

namespace fs = std::filesystem;

TEST(CliConvert, HelpAndVersion) {
  const auto help = matbake({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("convert"), std::string::npos);
  const auto convert_help = matbake({"convert", "--help"});
  EXPECT_EQ(convert_help.exit_code, 0);
  EXPECT_NE(convert_help.out.find("--out-dir"), std::string::npos);
  const auto version = matbake({"--version"});
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.out.rfind("matbake 0.", 0), 0u) << version.out;
}

TEST(CliConvert, UsageErrorsExitTwo) {
  TempDir dir;
  write_raw(dir / "a.png", 1, 1, 3, "uint8", {1, 2, 3});
  const std::string a = (dir / "a.png").string();
  const std::vector<std::vector<std::string>> cases = {
      {},
      {"frobnicate"},
      {"convert"},
      {"convert", a},
      {"convert", a, a, "-o", (dir / "x.exr").string()},
      {"convert", a, "-o", (dir / "x.exr").string(), "--bits", "12"},
      {"convert", a, "-o", (dir / "x.exr").string(), "--from", "srgb", "--to", "Linear Rec.709 (sRGB)"},
      {"convert", a, "-o", (dir / "x.exr").string(), "--from", "sRGB - Texture", "--to", "nonsense"},
      {"convert", a, "-o", (dir / "x.jpg")},
      {"convert", a, "-o", (dir / "x.exr").string(), "--bits", "8"},
      {"convert", a, "-o", (dir / "x.exr").string(), "--out-dir", dir.path().string()},
  };
  for (const auto& args : cases) {
    const auto r = matbake(args);
    EXPECT_EQ(r.exit_code, 2) << testing::PrintToString(args) << r.err;
    EXPECT_EQ(r.err.rfind("matbake: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_EQ(list_folder(dir.path()), std::vector<std::string>{"a.png"});
}

TEST(CliConvert, RgbaPngToLinearExrAndBackIsBitExact) {
  TempDir dir;
  write_raw(dir / "in.png", 1, 1, 4, "uint8", {255, 128, 64, 128});
  const auto to_linear = matbake({"convert", (dir / "in.png").string(), "-o", (dir / "lin.exr").string()});
  ASSERT_EQ(to_linear.exit_code, 0) << to_linear.err;
  const auto exr = read_raw(dir / "lin.exr");
  EXPECT_EQ(exr.format, "half");
  EXPECT_EQ(exr.samples[0], 1.0);
  EXPECT_NEAR(exr.samples[1], 0.2158605, 1e-4);  // half of the sRGB decode of 128
  EXPECT_EQ(exr.samples[3], 0.501953125);        // half(128/255): alpha linear, not divided
  const auto back = matbake({"convert", (dir / "lin.exr").string(), "-o", (dir / "back.png").string(), "--from",
                             "linear", "--to", "srgb", "--bits", "8"});
  ASSERT_EQ(back.exit_code, 0) << back.err;
  EXPECT_EQ(read_raw(dir / "back.png").samples, (std::vector<double>{255, 128, 64, 128}));
}

TEST(CliConvert, InputFormatsAndLayouts) {
  TempDir dir;
  write_raw(dir / "gray_alpha.png", 3, 3, 2, "uint8", std::vector<double>(18, 100));
  write_raw(dir / "rgb16.tif", 5, 1, 3, "uint16", std::vector<double>(15, 40000));
  write_raw(dir / "photo.jpg", 8, 8, 3, "uint8", std::vector<double>(192, 180));
  write_raw(dir / "half.exr", 2, 1, 1, "half", {0.5, 2.0});
  const auto r = matbake({"convert", (dir / "gray_alpha.png").string(), (dir / "rgb16.tif").string(),
                          (dir / "photo.jpg").string(), (dir / "half.exr").string(), "--out-dir",
                          (dir / "out").string(), "--format", "tif", "--bits", "float"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto gray = read_raw(dir / "out/gray_alpha.tif");
  EXPECT_EQ(gray.channels, 2);
  EXPECT_FLOAT_EQ(float(gray.samples[0]), float(std::pow((100 / 255.0 + 0.055) / 1.055, 2.4)));
  EXPECT_FLOAT_EQ(float(gray.samples[1]), float(100 / 255.0));
  EXPECT_FLOAT_EQ(float(read_raw(dir / "out/rgb16.tif").samples[0]), float(std::pow((40000 / 65535.0 + 0.055) / 1.055, 2.4)));
  EXPECT_EQ(read_raw(dir / "out/photo.tif").width, 8);
  const auto hdr = read_raw(dir / "out/half.tif");
  EXPECT_FLOAT_EQ(float(hdr.samples[1]), float(std::pow(2.055 / 1.055, 2.4)));
}

TEST(CliConvert, JsonAndQuiet) {
  TempDir dir;
  write_raw(dir / "a.png", 4, 2, 3, "uint8", std::vector<double>(24, 9));
  const auto json = matbake({"convert", (dir / "a.png").string(), "-o", (dir / "a.exr").string(), "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto parsed = nlohmann::json::parse(json.out);
  EXPECT_EQ(parsed["command"], "convert");
  ASSERT_EQ(parsed["results"].size(), 1u);
  EXPECT_EQ(parsed["results"][0]["width"], 4);
  EXPECT_EQ(parsed["results"][0]["output_type"], "half");
  EXPECT_EQ(parsed["results"][0]["output"], (dir / "a.exr").string());

  const auto quiet = matbake({"--quiet", "convert", (dir / "a.png").string(), "-o", (dir / "b.exr").string()});
  EXPECT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.out, "");
  EXPECT_EQ(quiet.err, "");
  const auto loud = matbake({"convert", (dir / "a.png").string(), "-o", (dir / "c.exr").string()});
  EXPECT_NE(loud.out.find("-> "), std::string::npos);
}

TEST(CliConvert, BadInputsExitOneWithOneLineNamingTheFile) {
  TempDir dir;
  write_raw(dir / "good.png", 64, 64, 3, "uint8", std::vector<double>(64 * 64 * 3, 120));
  const std::string good = read_bytes(dir / "good.png");
  write_bytes(dir / "truncated.png", good.substr(0, good.size() / 2));
  write_bytes(dir / "text.png", "not an image\n");
  write_raw(dir / "five.exr", 2, 2, 5, "half", std::vector<double>(20, 0.5));
  write_raw(dir / "nan.exr", 2, 1, 1, "float", {std::nan(""), 0.5});
  write_bytes(dir / "previous.exr", "previous good output");
  const auto files_before = list_folder(dir.path());

  struct Case {
    std::string input;
    std::string problem;
  };
  const std::vector<Case> cases = {
      {(dir / "missing.png").string(), "no such file"},
      {(dir / "text.png").string(), "not a readable image"},
      {(dir / "truncated.png").string(), "cannot read pixels"},
      {(dir / "five.exr").string(), "5 channels; matbake reads 1 to 4"},
      {(dir / "nan.exr").string(), "contains 1 NaN and 0 Inf samples"},
  };
  for (const Case& c : cases) {
    const auto r = matbake({"convert", c.input, "-o", (dir / "previous.exr").string()});
    EXPECT_EQ(r.exit_code, 1) << c.input;
    expect_one_error_line(r, c.input, c.problem);
  }
  // The existing output is untouched and no temporary file is left.
  EXPECT_EQ(read_bytes(dir / "previous.exr"), "previous good output");
  EXPECT_EQ(list_folder(dir.path()), files_before);

  // Output path equal to the input.
  const auto same = matbake({"convert", (dir / "good.png").string(), "-o", (dir / "good.png").string()});
  EXPECT_EQ(same.exit_code, 2);  // a usage error, as for every command
  expect_one_error_line(same, (dir / "good.png").string(), "is an input; matbake never overwrites its inputs");
  // An output folder that cannot be made (under a file); a missing one is made.
  const auto no_folder = matbake({"convert", (dir / "good.png").string(), "-o", (dir / "good.png/x.exr").string()});
  EXPECT_EQ(no_folder.exit_code, 1);
  expect_one_error_line(no_folder, (dir / "good.png/x.exr").string(), "cannot make the output folder: ");
  const auto new_folder = matbake({"convert", (dir / "good.png").string(), "-o", (dir / "made/x.exr").string()});
  EXPECT_EQ(new_folder.exit_code, 0) << new_folder.err;
  EXPECT_TRUE(fs::is_regular_file(dir / "made/x.exr"));
  EXPECT_EQ(read_bytes(dir / "good.png"), good);
}

TEST(CliConvert, UnwritableOutputFolder) {
  TempDir dir;
  write_raw(dir / "in.png", 2, 2, 3, "uint8", std::vector<double>(12, 1));
  fs::create_directory(dir / "locked");
  fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                      fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(dir.path(), fs::perms::others_read | fs::perms::others_exec, fs::perm_options::add);
  const std::vector<std::string> args = {"convert", (dir / "in.png").string(), "-o", (dir / "locked/out.exr").string()};
  RunResult r;
  if (geteuid() == 0) {
    // Root writes anywhere: run as nobody, for whom the folder is read-only. The build folder may
    // not be readable by nobody (a clone in a 0700 temp folder), so run copies from ours.
    if (!fs::exists("/usr/bin/setpriv")) GTEST_SKIP() << "running as root without setpriv";
    const fs::path exe = MATBAKE_EXE;
    fs::create_directory(dir / "bin");
    fs::copy_file(exe, dir / "bin/matbake");
    for (const auto& entry : fs::directory_iterator(exe.parent_path().parent_path() / "lib")) {
      if (entry.path().filename().string().rfind("libmatbake.so", 0) == 0) {
        fs::copy(entry.path(), dir / "bin" / entry.path().filename(), fs::copy_options::copy_symlinks);
      }
    }
    std::vector<std::string> as_nobody = {"--reuid=65534", "--regid=65534", "--clear-groups",
                                          (dir / "bin/matbake").string()};
    as_nobody.insert(as_nobody.end(), args.begin(), args.end());
    r = run("/usr/bin/setpriv", as_nobody, {"LD_LIBRARY_PATH=" + (dir / "bin").string()});
  } else {
    r = matbake(args);
  }
  EXPECT_EQ(r.exit_code, 1) << r.err;
  expect_one_error_line(r, (dir / "locked/out.exr").string(), "cannot write in the output folder: Permission denied");
  EXPECT_TRUE(fs::is_empty(dir / "locked"));
}

TEST(CliConvert, BatchFinishesPastABadFileAndSummarises) {
  TempDir dir;
  write_raw(dir / "a.png", 2, 2, 3, "uint8", std::vector<double>(12, 1));
  write_bytes(dir / "b.png", "garbage");
  write_raw(dir / "c.png", 2, 2, 3, "uint8", std::vector<double>(12, 2));
  const auto r = matbake({"convert", (dir / "a.png").string(), (dir / "b.png").string(), (dir / "c.png").string(),
                          "--out-dir", (dir / "out").string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(list_folder(dir / "out"), (std::vector<std::string>{"a.exr", "c.exr"}));
  EXPECT_NE(r.err.find("matbake: error: " + (dir / "b.png").string() + ": not a readable image"), std::string::npos);
  EXPECT_NE(r.err.find("matbake: 1 of 3 conversions failed"), std::string::npos);
}

TEST(CliConvert, OutDirCollisionIsRefusedBeforeAnyWork) {
  TempDir dir;
  fs::create_directories(dir / "x");
  write_raw(dir / "a.png", 1, 1, 3, "uint8", {1, 2, 3});
  write_raw(dir / "x/a.png", 1, 1, 3, "uint8", {1, 2, 3});
  const auto r = matbake({"convert", (dir / "a.png").string(), (dir / "x/a.png").string(), "--out-dir",
                          (dir / "out").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(CliConvert, OutputIsByteIdenticalAcrossRunsAndThreadCounts) {
  TempDir dir;
  std::vector<double> codes(300 * 200 * 4);
  for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = double((i * 2654435761u) % 256);
  write_raw(dir / "in.png", 300, 200, 4, "uint8", codes);
  // A second apart, so a timestamp in the file would show (OIIO writes one unless told not to).
  for (const char* ext : {".exr", ".tif"}) {
    for (const char* jobs : {"1", "2"}) {
      const auto r = matbake({"convert", (dir / "in.png").string(), "-o", (dir / (jobs + std::string(ext))).string(),
                              "--jobs", jobs});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      if (std::string(jobs) == "1") sleep(1);
    }
    EXPECT_EQ(read_bytes(dir / ("1" + std::string(ext))), read_bytes(dir / ("2" + std::string(ext)))) << ext;
  }
}

TEST(CliConvert, OcioConfigOptionAndVariable) {
  TempDir dir;
  write_raw(dir / "in.png", 2, 1, 3, "uint8", {10, 128, 255, 0, 1, 2});
  const std::vector<std::string> args = {"convert", (dir / "in.png").string(), "-o", (dir / "o.exr").string(),
                                         "--from", "sRGB - Texture", "--to", "Linear Rec.709 (sRGB)"};
  const auto builtin = matbake(args, {"OCIO="});
  ASSERT_EQ(builtin.exit_code, 0) << builtin.err;
  const auto missing_env = matbake(args, {"OCIO=" + (dir / "none.ocio").string()});
  EXPECT_EQ(missing_env.exit_code, 1);
  expect_one_error_line(missing_env, (dir / "none.ocio").string(), "OCIO config not found");
  auto with_option = args;
  with_option.insert(with_option.begin(), {"--ocio-config", (dir / "none2.ocio").string()});
  const auto missing_option = matbake(with_option);
  EXPECT_EQ(missing_option.exit_code, 1);
  expect_one_error_line(missing_option, (dir / "none2.ocio").string(), "OCIO config not found");
}

}  // namespace
}  // namespace matbake::test

namespace matbake::test {
namespace {

TEST(CliPreview, WritesPngAndSidecarAndRefusesBadParameters) {
  TempDir dir;
  const auto ok = matbake({"preview", "-o", (dir / "ball.png").string(), "--kd", "0.8,0.2,0.1", "--gloss-sweep",
                           "0.25,1", "--size", "32"});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto png = read_raw(dir / "ball.png");
  EXPECT_EQ(png.width, 64);
  EXPECT_EQ(png.height, 32);
  EXPECT_EQ(png.format, "uint8");
  const auto sidecar = nlohmann::json::parse(read_bytes(dir / "ball.json"));
  EXPECT_EQ(sidecar["cells"].size(), 2u);
  EXPECT_EQ(sidecar["cells"][1]["gloss"], 1.0);

  const std::vector<std::vector<std::string>> usage = {
      {"preview", "-o", (dir / "x.png").string(), "--gloss", "1.2"},
      {"preview", "-o", (dir / "x.png").string(), "--kd", "-0.5"},
      {"preview", "-o", (dir / "x.png").string(), "--ks", "0.1,0.2"},
      {"preview", "-o", (dir / "x.png").string(), "--model", "nope"},
      {"preview", "-o", (dir / "x.exr").string()},
  };
  for (const auto& args : usage) {
    const auto r = matbake(args);
    EXPECT_EQ(r.exit_code, 2) << testing::PrintToString(args) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  // Textures, as pack reads them (issue "One request layer": `--kd rgba.png` was "not a number").
  write_raw(dir / "kd.png", 4, 2, 4, "uint8", {200, 20, 20, 255, 20, 200, 20, 255, 20, 20, 200, 255, 90, 90, 90, 255,
                                               200, 20, 20, 255, 20, 200, 20, 255, 20, 20, 200, 255, 90, 90, 90, 255});
  write_raw(dir / "b.png", 4, 2, 4, "uint8", std::vector<double>(32, 128));
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--kd", (dir / "kd.png").string(), "--gloss", "0.7"},
           {"--from", "schuler", (dir / "kd.png").string(), (dir / "b.png").string()},
           {"--base-color", (dir / "kd.png").string(), "--metallic", "1"}}) {
    std::vector<std::string> all = {"preview", "-o", (dir / "textured.png").string(), "--size", "16"};
    all.insert(all.end(), args.begin(), args.end());
    const auto textured = matbake(all);
    ASSERT_EQ(textured.exit_code, 0) << textured.err;
    const auto cells = nlohmann::json::parse(read_bytes(dir / "textured.json"))["cells"];
    EXPECT_TRUE(cells[0]["textured"]) << args[0];
  }
  write_bytes(dir / "bad.json", "not json");
  const auto bad = matbake({"preview", "-o", (dir / "x.png").string(), "--materials", (dir / "bad.json").string()});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

}  // namespace
}  // namespace matbake::test
