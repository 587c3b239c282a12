#pragma once
// Small glTF files for tests, written by hand: a JSON document whose single buffer is a data: URI
// (or an external .bin beside it) holding the given floats and indices.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace matbake::gltf {
struct Document;
}

namespace matbake::test {

struct GltfBuilder {
  std::vector<unsigned char> bytes;
  nlohmann::json doc = {{"asset", {{"version", "2.0"}}}, {"buffers", nlohmann::json::array()},
                        {"bufferViews", nlohmann::json::array()}, {"accessors", nlohmann::json::array()},
                        {"meshes", nlohmann::json::array()}, {"nodes", nlohmann::json::array()}};
  // Appends data and an accessor over it; returns the accessor index.
  int add_vec3(const std::vector<float>& xyz);
  int add_floats(const std::vector<float>& values, const std::string& type, int components);
  int add_indices(const std::vector<std::uint32_t>& indices);
  // A mesh with one primitive; returns the mesh index.
  int add_mesh(int positions, int indices = -1, int mode = 4, int normals = -1);
  int add_node(nlohmann::json node);
  bool external_bin = false;  // the buffer as <stem>.bin beside the file, else a data: URI
  // Finishes the buffer and writes the file; `scene_nodes` become scene 0, the default.
  void write(const std::filesystem::path& path, const std::vector<int>& scene_nodes);
};

std::string base64(const std::vector<unsigned char>& bytes);

// A written glTF read back (its JSON and buffers); a failure to read fails the test.
gltf::Document read_output(const std::filesystem::path& path);

// The floats of a float accessor (SCALAR, VEC2/3/4), read from a document's own bytes.
std::vector<float> float_accessor(const gltf::Document& doc, int index);

}  // namespace matbake::test
