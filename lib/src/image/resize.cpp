#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "matbake/image.hpp"

namespace matbake::image {

Image resize_image(const Image& image, int width, int height) {
  namespace OIIO = OIIO_NAMESPACE;
  const OIIO::ImageSpec source_spec(image.width, image.height, image.channels, OIIO::TypeDesc::FLOAT);
  // OIIO wraps the caller's buffer read-only here; it never writes through the pointer.
  const OIIO::ImageBuf source(source_spec, const_cast<float*>(image.pixels.data()));
  OIIO::ImageBuf resized(OIIO::ImageSpec(width, height, image.channels, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::resize(resized, source);
  Image out;
  static_cast<ImageLayout&>(out) = image;
  out.width = width;
  out.height = height;
  reserve_pixels(out.pixels, out.sample_count());
  out.pixels.resize(out.sample_count());
  resized.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, out.pixels.data());
  return out;
}

}  // namespace matbake::image
