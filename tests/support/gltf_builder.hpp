#pragma once
// Small glTF files written by hand, for the tests and the bake bench's pairs: a JSON document whose
// single buffer is a data: URI (or an external .bin beside it) holding the given floats and indices.
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include <array>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

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

// One mesh of one primitive with a dark grey rough dielectric material (a render of it is not clipped
// to white): positions, normals (none when empty), UVs as TEXCOORD_0 and linear RGB vertex colours
// as COLOR_0 (each none when empty).
void write_grey_mesh(const std::filesystem::path& path, const std::vector<glm::dvec3>& positions,
                     const std::vector<glm::dvec3>& normals, const std::vector<glm::vec2>& texcoords,
                     const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<glm::dvec3>& colors = {});

}  // namespace matbake::test
