#pragma once
// 8-bit images (pictures, screenshots, goldens, stamps) read and written through GDAL: PNG out,
// any 8-bit raster GDAL reads in (render/image_io.hpp names them with the EXR writer).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::gis {

/// An 8-bit image, rows top first, channels interleaved.
struct Image8 {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;
};

/// Writes 8-bit pixels (rows top first, 1-4 channels interleaved: grey, grey + alpha, RGB, RGBA)
/// to `path` as a PNG (GDAL's PNG driver, zlib level 6); `path` must end in .png (any case).
/// Writes no sidecar file.
Status writeImage8(const std::string& path, int width, int height, int channels, std::span<const uint8_t> pixels);

/// Reads an 8-bit raster (PNG, JPEG, an 8-bit TIFF, ...) with up to 4 bands. Other sample types
/// are refused, naming the type (a float DEM is not an image).
Result<Image8> readImage8(const std::string& path);

}  // namespace strata::gis
