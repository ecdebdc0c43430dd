#include <strata/gis/image8.hpp>

#include <cpl_conv.h>
#include <strings.h>

#include <filesystem>

#include "gdal_util.hpp"

namespace strata::gis {

Status writeImage8(const std::string& path, int width, int height, int channels, std::span<const uint8_t> pixels) {
  if (strcasecmp(std::filesystem::path(path).extension().c_str(), ".png") != 0) {
    return fail(path + ": colour images are written as PNG: name the file .png");
  }
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4) {
    return fail(path + ": a PNG needs a size and 1-4 channels, not " + std::to_string(width) + "x" +
                std::to_string(height) + "x" + std::to_string(channels));
  }
  if (pixels.size() != size_t(width) * size_t(height) * size_t(channels)) {
    return fail(path + ": " + std::to_string(pixels.size()) + " bytes for a " + std::to_string(width) + "x" +
                std::to_string(height) + "x" + std::to_string(channels) + " image");
  }
  detail::ensureGdal();
  detail::GdalErrorCapture errors;
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* png = GetGDALDriverManager()->GetDriverByName("PNG");
  if (!mem || !png) return fail(path + ": GDAL has no " + std::string(mem ? "PNG" : "MEM") + " driver");
  detail::DatasetPtr image(mem->Create("", width, height, channels, GDT_Byte, nullptr));
  if (!image) return fail(path + ": " + errors.last("cannot hold the image"));
  const int stride = channels;
  if (image->RasterIO(GF_Write, 0, 0, width, height, const_cast<uint8_t*>(pixels.data()), width, height, GDT_Byte,
                      channels, nullptr, stride, GSpacing(stride) * width, 1, nullptr) != CE_None) {
    return fail(path + ": " + errors.last("cannot hold the image"));
  }
  if (channels == 2 || channels == 4) image->GetRasterBand(channels)->SetColorInterpretation(GCI_AlphaBand);
  const char* options[] = {"ZLEVEL=6", "WORLDFILE=NO", nullptr};
  // No .aux.xml beside the picture: nothing here is georeferenced.
  CPLConfigOptionSetter noPam("GDAL_PAM_ENABLED", "NO", true);
  detail::DatasetPtr out(
      png->CreateCopy(path.c_str(), image.get(), FALSE, const_cast<char**>(options), nullptr, nullptr));
  if (!out)
    return fail(path + ": cannot write the PNG: " + detail::withoutPath(errors.last("GDAL gave no reason"), path));
  return {};
}

Result<Image8> readImage8(const std::string& path) {
  STRATA_TRY(detail::DatasetPtr ds, detail::openRaster(path));
  detail::GdalErrorCapture errors;
  Image8 img;
  img.width = ds->GetRasterXSize();
  img.height = ds->GetRasterYSize();
  img.channels = ds->GetRasterCount();
  if (img.channels < 1 || img.channels > 4) {
    return fail(path + ": an image has 1-4 bands, this has " + std::to_string(img.channels));
  }
  const GDALDataType type = ds->GetRasterBand(1)->GetRasterDataType();
  if (type != GDT_Byte) return fail(path + ": not an 8-bit image (its samples are " + GDALGetDataTypeName(type) + ")");
  img.pixels.resize(size_t(img.width) * size_t(img.height) * size_t(img.channels));
  const int stride = img.channels;
  if (ds->RasterIO(GF_Read, 0, 0, img.width, img.height, img.pixels.data(), img.width, img.height, GDT_Byte,
                   img.channels, nullptr, stride, GSpacing(stride) * img.width, 1, nullptr) != CE_None) {
    return fail(path + ": read failed: " + errors.last("GDAL gave no reason"));
  }
  return img;
}

}  // namespace strata::gis
