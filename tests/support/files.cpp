#include "support/files.hpp"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace matbake::test {

void write_raw(const std::filesystem::path& path, int width, int height, int channels, const std::string& format,
               const std::vector<double>& samples, std::vector<std::string> channel_names) {
  const OIIO::TypeDesc type(format);
  OIIO::ImageSpec spec(width, height, channels, type);
  if (!channel_names.empty()) spec.channelnames = std::move(channel_names);
  spec.alpha_channel = channels == 2 || channels == 4 ? channels - 1 : -1;
  spec.attribute("oiio:UnassociatedAlpha", 1);
  // Integer formats take codes: hand OIIO the samples in their own type.
  std::vector<uint16_t> codes(samples.begin(), samples.end());
  std::vector<uint8_t> bytes(samples.begin(), samples.end());
  std::vector<float> values(samples.begin(), samples.end());
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out || !out->open(path.string(), spec)) throw std::runtime_error("cannot write " + path.string());
  bool ok = false;
  if (type == OIIO::TypeDesc::UINT8) ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  else if (type == OIIO::TypeDesc::UINT16) ok = out->write_image(OIIO::TypeDesc::UINT16, codes.data());
  else ok = out->write_image(OIIO::TypeDesc::FLOAT, values.data());
  if (!ok || !out->close()) throw std::runtime_error("cannot write " + path.string() + ": " + out->geterror());
}

RawImage read_raw(const std::filesystem::path& path) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  if (!in) throw std::runtime_error("cannot read " + path.string() + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  RawImage image{spec.width, spec.height, spec.nchannels, spec.format.c_str(), spec.channelnames, {}};
  std::vector<double> values(std::size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::DOUBLE, values.data())) {
    throw std::runtime_error("cannot read " + path.string() + ": " + in->geterror());
  }
  // Back to codes for integer formats (OIIO normalises them to [0, 1]).
  const double scale = spec.format == OIIO::TypeDesc::UINT8 ? 255.0 : spec.format == OIIO::TypeDesc::UINT16 ? 65535.0 : 1.0;
  for (double& v : values) v = scale == 1.0 ? v : std::round(v * scale);
  image.samples = std::move(values);
  return image;
}

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::vector<std::string> list_folder(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void copy_example(const std::filesystem::path& dir, bool few_samples) {
  namespace fs = std::filesystem;
  for (const char* f : {"showroom.toml", "showroom.gltf", "showroom.bin"}) fs::copy_file(kExamples / f, dir / f);
  fs::copy(kExamples / "textures", dir / "textures", fs::copy_options::recursive);
  if (few_samples) {
    std::string text = read_bytes(dir / "showroom.toml");
    const std::size_t at = text.find("samples = 128");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 13, "samples = 16");
    write_bytes(dir / "showroom.toml", text);
  }
}

}  // namespace matbake::test
