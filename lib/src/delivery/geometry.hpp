#pragma once
// Meshes made ready for delivery (docs/delivery.md, "Geometry"): triangle lists reordered for the
// vertex cache and vertex fetch, attributes quantized (KHR_mesh_quantization), vertex and index
// buffers compressed (EXT_meshopt_compression), all through meshoptimizer; identical results stored
// once. Run last, on a document about to be written: AO and texel density read the geometry as it
// came.
#include <string>
#include <vector>

#include "../gltf/document.hpp"
#include "matbake/delivery.hpp"

namespace matbake::delivery {

// The largest error quantization allows, per attribute (docs/delivery.md states them; the tests hold
// the written files to them). Positions: half a grid step along each axis, the step being the mesh's
// longest side over 2^bits − 1; texture coordinates: half a step of the set's range over
// 2^bits − 1; normals and tangents: a component within 0.5 / 127 of the unit vector's;
// colours: 0.5 / 255.
double position_error_bound(double longest_side, int bits);
double texcoord_error_bound(double range, int bits);
inline constexpr double kNormalComponentError = 0.5 / 127, kColourError = 0.5 / 255;

// Rewrites doc's triangle lists as `options` says (GeometryOptions) and returns lines for the report.
// Primitives of other modes and with morph targets are kept as read. Errors name the file and the
// primitive (`/meshes/2/primitives/0`).
Result<std::vector<std::string>> deliver_geometry(gltf::Document& doc, const GeometryOptions& options);

}  // namespace matbake::delivery
