#pragma once
// The flattened scene of a glTF document already in memory: export and bake-ao read the file once
// and take both the scene to bake and the document to write from it.
#include "../gltf/document.hpp"
#include "matbake/scene.hpp"

namespace matbake::scene {

Result<Scene> scene_from_document(const gltf::Document& doc, const SceneContent& content = {});

// A node's own transform: its matrix, else translation · rotation · scale (identity where absent).
glm::dmat4 local_matrix(const gltf::Json& node);

}  // namespace matbake::scene
