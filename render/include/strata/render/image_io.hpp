#pragma once
// Image files for renders and golden tests (OpenImageIO, kept out of other headers): PNG for
// colour, EXR for float fields (depth, elevation).

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::render {

/// An 8-bit image, rows top first, channels interleaved.
struct Image8 {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;
};

/// Writes 8-bit pixels (rows top first) to a PNG (or any format OIIO picks from the extension).
Status writeImage8(const std::string& path, int width, int height, int channels, std::span<const uint8_t> pixels);
/// Writes float pixels (rows top first) to an EXR.
Status writeImageFloat(const std::string& path, int width, int height, int channels, std::span<const float> pixels);
/// Reads an image as 8-bit.
Result<Image8> readImage8(const std::string& path);

}  // namespace strata::render
