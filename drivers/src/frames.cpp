#include "romo/drivers/frames.hpp"

#include "romo/core/check.hpp"

namespace romo::drivers {

int BytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::kMono8: return 1;
    case PixelFormat::kMono16: return 2;
    case PixelFormat::kRgb8: return 3;
  }
  Fail("unknown pixel format " + std::to_string(static_cast<int>(format)));
}

const char* ToString(PixelFormat format) {
  switch (format) {
    case PixelFormat::kMono8: return "mono8";
    case PixelFormat::kMono16: return "mono16";
    case PixelFormat::kRgb8: return "rgb8";
  }
  return "unknown";
}

Image Image::Allocate(PixelFormat format, int width, int height) {
  ROMO_THROW_UNLESS(width >= 0 && height >= 0);
  Image image;
  image.format = format;
  image.width = width;
  image.height = height;
  image.stride_bytes = width * BytesPerPixel(format);
  image.data.assign(static_cast<std::size_t>(image.stride_bytes) * height, 0);
  return image;
}

void Image::Validate() const {
  if (width < 0 || height < 0) {
    Fail("image has negative size " + std::to_string(width) + "x" + std::to_string(height));
  }
  const int min_stride = width * BytesPerPixel(format);
  if (stride_bytes < min_stride) {
    Fail("image stride " + std::to_string(stride_bytes) + " bytes is below width x bytes per pixel = " +
         std::to_string(min_stride));
  }
  const std::size_t needed = static_cast<std::size_t>(stride_bytes) * height;
  if (data.size() < needed) {
    Fail("image buffer holds " + std::to_string(data.size()) + " bytes, " +
         std::to_string(width) + "x" + std::to_string(height) + " " + ToString(format) +
         " needs " + std::to_string(needed));
  }
}

}  // namespace romo::drivers
