#include <strata/render/image_io.hpp>

#include <OpenImageIO/imageio.h>

#include <strata/core/files.hpp>

namespace strata::render {
namespace {

Status writeImage(const std::string& path, int width, int height, int channels, OIIO::TypeDesc type, const void* data) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return fail(path + ": cannot create an image writer: " + OIIO::geterror());
  OIIO::ImageSpec spec(width, height, channels, type);
  if (type == OIIO::TypeDesc::FLOAT) spec.attribute("compression", "zip");
  if (!out->open(path, spec)) return fail(path + ": cannot open for writing: " + out->geterror());
  if (!out->write_image(type, data)) return fail(path + ": write failed: " + out->geterror());
  if (!out->close()) return fail(path + ": close failed: " + out->geterror());
  return {};
}

}  // namespace

Status writeImage8(const std::string& path, int width, int height, int channels, std::span<const uint8_t> pixels) {
  if (pixels.size() != size_t(width) * size_t(height) * size_t(channels)) {
    return fail(path + ": " + std::to_string(pixels.size()) + " bytes for a " + std::to_string(width) + "x" +
                std::to_string(height) + "x" + std::to_string(channels) + " image");
  }
  return writeImage(path, width, height, channels, OIIO::TypeDesc::UINT8, pixels.data());
}

Status writeImageFloat(const std::string& path, int width, int height, int channels, std::span<const float> pixels) {
  if (pixels.size() != size_t(width) * size_t(height) * size_t(channels)) {
    return fail(path + ": " + std::to_string(pixels.size()) + " floats for a " + std::to_string(width) + "x" +
                std::to_string(height) + "x" + std::to_string(channels) + " image");
  }
  return writeImage(path, width, height, channels, OIIO::TypeDesc::FLOAT, pixels.data());
}

Result<Image8> readImage8(const std::string& path) {
  STRATA_TRY_STATUS(requireRegularFile(path, "an image"));
  auto in = OIIO::ImageInput::open(path);
  if (!in) return fail(path + ": cannot read: " + OIIO::geterror());
  const auto& spec = in->spec();
  Image8 img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::UINT8, img.pixels.data())) {
    return fail(path + ": read failed: " + in->geterror());
  }
  in->close();
  return img;
}

}  // namespace strata::render
