// An OpenEXR header checked by OpenEXR's C core before OIIO's reader (OpenEXR's C++ library)
// opens the file.
#pragma once

#include <OpenImageIO/filesystem.h>

#include <optional>
#include <string>

namespace matbake::image {

// OpenEXR 3.1's C++ header reader allocates (and clears) the size an attribute declares before
// reading its bytes, and reads typed attributes by their content rather than their declared size:
// a 296-byte file declaring a 2 GB string cost 2.2 GB and 7.5 s before "unexpected end of file".
// OpenEXR's C core parses the same header with every size checked against the type and the file;
// a header it refuses is returned as the problem (its message). Not an OpenEXR file: no problem.
// (OIIO 2.4's reader on top of the core is not used: it divides by zero on some files it accepts.)
std::optional<std::string> exr_header_problem(OIIO::Filesystem::IOProxy& file);

}  // namespace matbake::image
