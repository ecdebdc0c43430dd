#pragma once
// Image files for renders and golden tests: PNG for colour (through GDAL, strata/gis/image8.hpp),
// EXR for float fields (depth, elevation, generated heights; OpenEXR). Neither library's headers
// reach the callers.

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/gis/image8.hpp>

namespace strata::render {

/// 8-bit images: PNG out, any 8-bit raster in (gis/image8.hpp).
using gis::Image8;
using gis::readImage8;
using gis::writeImage8;

/// What an EXR carries besides its pixels: channel names (default: "Y" for one channel, else
/// R, G, B, A) and string and integer header attributes (e.g. "strata:seed").
struct ExrExtras {
  std::vector<std::string> channelNames;
  std::vector<std::pair<std::string, std::string>> strings;
  std::vector<std::pair<std::string, int>> ints;
};

/// Writes float pixels (rows top first, 1-4 channels interleaved) to a ZIP-compressed EXR.
Status writeImageFloat(const std::string& path, int width, int height, int channels, std::span<const float> pixels,
                       const ExrExtras& extras = {});

}  // namespace strata::render
