#pragma once
// Per-vertex occlusion written into a glTF document: COLOR_0 (alone, or times the file's colours)
// or an `_AO` attribute, per primitive placed by a node. A mesh placed by several nodes gets a copy
// per further node (sharing every accessor but the new one), since each placement has its own values.
#include <glm/vec4.hpp>

#include <span>
#include <string>

#include "document.hpp"
#include "matbake/ao.hpp"  // ao::Into: the option's public name

namespace matbake::gltf {

struct PlacedValues {
  int node = -1;       // the node placing the mesh (its mesh is read from the document)
  int primitive = -1;  // of that mesh
  std::span<const float> values;         // one per vertex
  std::span<const glm::vec4> colors;     // the file's COLOR_0 as floats; empty when it has none
  bool colors_have_alpha = false;
};

void add_vertex_occlusion(Document& doc, std::span<const PlacedValues> placed, ao::Into into);

// The same placements' values as `attribute` (one float per vertex, "_THICKNESS"): its colours unused.
void add_vertex_scalars(Document& doc, std::span<const PlacedValues> placed, const std::string& attribute);

}  // namespace matbake::gltf
