#pragma once
// Geometry a glTF stores compressed or sparse, decoded once when the document is read, so that every
// reader of accessors (accessor_bytes) sees plain elements: EXT_meshopt_compression buffer views
// (meshoptimizer's decoders and filters), KHR_draco_mesh_compression primitives (Draco's decoder)
// and sparse accessors (their substitutions applied). The document's JSON and buffers are not
// changed: what matbake does not rewrite is written back as it came, compressed.
#include "document.hpp"

namespace matbake::gltf {

// Decodes into doc.decoded. Errors name the file and the object (`/bufferViews/3`).
Status decode_meshopt_views(Document& doc);
Status decode_draco_and_sparse(Document& doc);

// Whether buffer `index` is a meshopt fallback: no bytes of its own, only decoded views over it.
bool is_fallback_buffer(const Json& json, std::size_t index);

// Gives the Draco primitive at mesh `m`, primitive `p` plain accessors again: each of its decoded
// accessors gets a buffer view with the decoded bytes, and the extension is removed from it (from
// the file's extension lists too when no primitive uses it any more). For a primitive matbake
// changes: it is written uncompressed. Returns false when the primitive was not Draco-compressed.
bool uncompress_draco_primitive(Document& doc, std::size_t m, std::size_t p);

// For the report, once the document is ready to write: each Draco primitive (decoded to read; passed
// through compressed, or written uncompressed where matbake changed it), the meshopt views and the
// sparse accessors (decoded to read, written as they came).
std::vector<std::string> geometry_notes(const Document& doc);

}  // namespace matbake::gltf
