#pragma once
// Keeping only what a glTF's default scene reaches, as gltf-transform's prune does: meshes placed
// by the scene's nodes, the materials their primitives use, the textures those materials name (in
// the core and in any extension: every `...Texture` object with an index) and KHR_materials_variants
// names, their images and samplers, and the accessors and buffer views all of these read (with
// EXT_mesh_gpu_instancing's). Skins and animations keep what they reference. Nodes stay; one outside the scene loses its mesh when that is removed.
// The buffers are then compacted into one holding only the kept buffer views.
#include <string>
#include <vector>

#include "document.hpp"

namespace matbake::gltf {

// What the default scene reaches, per top-level array prune_unreachable shortens.
struct Reachable {
  std::vector<bool> meshes, materials, accessors, textures, images, samplers, views;
};
Reachable reachable(Json& json);

// Returns one line per removed object ("material 2 'Unused'"), for the report; `texture_remap`, when
// given, receives each old texture index's new one (−1: removed). With `before` (reachable() of the
// document before an edit that only appended), what was unreachable then stays: only what the edit
// left unused goes (a bake's replaced textures), not the file's own unused objects.
std::vector<std::string> prune_unreachable(Document& doc, std::vector<int>* texture_remap = nullptr,
                                           const Reachable* before = nullptr);

// Images with the same bytes become one: every texture's reference moves to the first of them; then
// textures that are the same (name aside) become one likewise, for every material. What is left
// unused goes with the next prune_unreachable. Returns each texture's index → the texture that
// now stands for it (itself when none does).
std::vector<int> merge_identical_images(Document& doc);

// Calls f(info) for every textureInfo of a material (an object under a key ending in "Texture" with
// an index), core and extensions alike.
void for_each_texture_info(Json& material, const std::function<void(Json& info)>& f);
// Calls f(index) for every texture index a material names, core and extensions alike.
void for_each_texture_index(Json& material, const std::function<void(Json& index)>& f);

}  // namespace matbake::gltf
