#include "support/gltf_files.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "lib/src/gltf/document.hpp"

namespace matbake::test {

gltf::Document read_output(const std::filesystem::path& path) {
  auto doc = gltf::read_document(path);
  EXPECT_TRUE(doc) << doc.error().to_string();
  return doc ? std::move(*doc) : gltf::Document{};
}

std::vector<float> float_accessor(const gltf::Document& doc, int index) {
  const gltf::Json& a = doc.json["accessors"][std::size_t(index)];
  const gltf::Json& view = doc.json["bufferViews"][a["bufferView"].get<std::size_t>()];
  EXPECT_EQ(a["componentType"], 5126);
  const std::string type = a["type"];
  const std::size_t components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
  std::vector<float> out(a["count"].get<std::size_t>() * components);
  const auto& buffer = doc.buffers[view["buffer"].get<std::size_t>()];
  const std::size_t offset = view.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
  EXPECT_LE(offset + out.size() * 4, buffer.size());
  if (offset + out.size() * 4 <= buffer.size()) std::memcpy(out.data(), buffer.data() + offset, out.size() * 4);
  return out;
}

}  // namespace matbake::test
