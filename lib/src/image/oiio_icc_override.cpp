// OIIO 2.4's (Debian's 2.4.7) ICC profile decoder follows the offsets of text tags ('desc', 'cprt',
// mluc records) past the profile: SIGSEGV on a PNG with a damaged iCCP chunk, found by
// tests/fuzz/fuzz_image, also reached from JPEG and TIFF; fixed upstream in later releases. It only
// fills ICCProfile:* description attributes, which matbake never reads; the profile's bytes stay
// in the "ICCProfile" attribute, set by each reader before this call.
//
// This definition replaces OIIO's: the readers call it through the PLT, and libmatbake is in the
// global lookup scope ahead of libOpenImageIO, whether OIIO comes in with the module that
// libmatbake loads (oiio_module.cpp) or with the program. It lives here, not in that module, for
// that reason, and needs OIIO's headers only (for the signature), not its library.
// tests/unit/test_image.cpp checks that it is the one in effect.
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/span.h>

#if OIIO_VERSION < OIIO_MAKE_VERSION(2, 5, 0)
OIIO_NAMESPACE_BEGIN

// The declaration is OIIO's (tiffutils.h, which needs libtiff's headers).
bool decode_icc_profile(cspan<uint8_t> iccdata, ImageSpec& spec, std::string& error);
bool decode_icc_profile(cspan<uint8_t> /*iccdata*/, ImageSpec& /*spec*/, std::string& /*error*/) {
  return true;
}

OIIO_NAMESPACE_END
#endif
