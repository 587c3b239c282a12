// Uses the installed library: decodes sRGB 128 and checks it against the IEC formula, then writes
// and reads back a TIFF, a format of OpenImageIO's (the installed module, loaded from beside the
// installed libmatbake), and a PNG (matbake's own codec).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <matbake/color.hpp>
#include <matbake/image.hpp>
#include <matbake/version.hpp>

namespace {

bool round_trips(const std::filesystem::path& file) {
  matbake::image::Image image;
  image.width = 2;
  image.height = 1;
  image.channels = 3;
  for (int code : {0, 65535, 1000, 30000, 12345, 7}) image.pixels.push_back(float(code / 65535.0));  // 16-bit codes
  matbake::image::WriteOptions options;
  options.type = matbake::image::SampleType::f32;
  if (file.extension() == ".png") options.type = matbake::image::SampleType::u16;
  if (auto s = matbake::image::write_image(image, file, options); !s) {
    std::printf("%s\n", s.error().to_string().c_str());
    return false;
  }
  auto back = matbake::image::read_image(file, matbake::color::Transfer::linear);
  if (!back) {
    std::printf("%s\n", back.error().to_string().c_str());
    return false;
  }
  return back->pixels == image.pixels;  // exact: 16-bit codes, and float
}

}  // namespace

int main(int, char** argv) {
  const float table = matbake::color::decode_table(matbake::color::Transfer::srgb, 8)[128];
  const double exact = std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4);
  std::printf("matbake %s: sRGB 128 -> %.9g (formula %.9g)\n", matbake::version, table, exact);
  const auto folder = std::filesystem::absolute(argv[0]).parent_path();
  const bool tiff = round_trips(folder / "round_trip.tif"), png = round_trips(folder / "round_trip.png");
  std::printf("TIFF (OpenImageIO module) round trip: %s; PNG: %s\n", tiff ? "exact" : "FAILED", png ? "exact" : "FAILED");
  return table == float(exact) && tiff && png ? 0 : 1;
}
