#pragma once
// glTF files for tests: written by hand (GltfBuilder) and read back.
#include <filesystem>
#include <vector>

#include "support/gltf_builder.hpp"

namespace matbake::gltf {
struct Document;
}

namespace matbake::test {

// A written glTF read back (its JSON and buffers); a failure to read fails the test.
gltf::Document read_output(const std::filesystem::path& path);

// The floats of a float accessor (SCALAR, VEC2/3/4), read from a document's own bytes.
std::vector<float> float_accessor(const gltf::Document& doc, int index);

}  // namespace matbake::test
