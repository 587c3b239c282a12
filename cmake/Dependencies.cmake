# Every dependency comes from Debian (scripts/deps.sh). See ../shared/design/DEBIAN-NOTES.md for
# why OpenImageIO and OpenColorIO are found through pkg-config rather than their CMake packages.
find_package(PkgConfig REQUIRED)
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO)
# 8/16-bit PNG is deflated by libdeflate (lib/src/image/png_encode.cpp); libspng reads it.
pkg_check_modules(deflate REQUIRED IMPORTED_TARGET libdeflate)
pkg_check_modules(spng REQUIRED IMPORTED_TARGET spng)
# Content hashes of the build's inputs (XXH64, as OIIO's copy computed them before).
pkg_check_modules(xxhash REQUIRED IMPORTED_TARGET libxxhash)
find_package(OpenEXR CONFIG REQUIRED)
find_package(Imath CONFIG REQUIRED)
find_package(glm CONFIG REQUIRED)
find_package(TinyGLTF CONFIG REQUIRED)
# Compressed glTF geometry (KHR_draco_mesh_compression, EXT_meshopt_compression) and WebP images.
find_package(draco CONFIG REQUIRED)
find_package(meshoptimizer CONFIG REQUIRED)
pkg_check_modules(webp REQUIRED IMPORTED_TARGET libwebp)
pkg_check_modules(zstd REQUIRED IMPORTED_TARGET libzstd)
find_package(embree 3 CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
# toml++ 3.3 (libtomlplusplus-dev): the material table and, later, build manifests are TOML.
find_package(tomlplusplus CONFIG REQUIRED)
