// A look at an OpenEXR header's attribute sizes before OpenEXR reads it.
#pragma once

#include <OpenImageIO/filesystem.h>

#include <optional>
#include <string>

namespace matbake::image {

// OpenEXR 3.1 allocates (and clears) the size an attribute declares before reading its bytes, so a
// 300-byte file that declares a 2 GB attribute costs 2 GB and seconds before "unexpected end of
// file". The header's attributes are walked first (names, types, sizes: nothing is decoded) and an
// attribute reaching beyond the end of the file is the problem returned. Files that are not
// OpenEXR, and other malformations, are left to the reader.
std::optional<std::string> exr_header_problem(OIIO::Filesystem::IOProxy& file);

}  // namespace matbake::image
