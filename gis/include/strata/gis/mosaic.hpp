#pragma once
// Mosaics: DEMs of any CRS, resolution and extent resampled (GDAL warp) onto one target grid and
// combined, in the order given, into a named layer with a blend mode. See docs/gis.md ("Mosaics").

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::gis {

/// How an input combines with the layer where both have data. Where the layer has no data yet,
/// every mode takes the input's value; where the input has no data, the layer is unchanged.
enum class BlendMode { Replace, Add, Subtract, Multiply, Max, Min };

/// Resampling kernel used when warping an input onto the target grid.
/// Minimum: each target cell takes the lowest source cell it covers (GDAL's "min"); coarsening a
/// DEM this way keeps narrow channels connected, which flow routing needs.
enum class Resampling { Nearest, Bilinear, Cubic, Minimum };

/// "replace", "add", "subtract", "multiply", "max", "min".
std::string_view toString(BlendMode mode);
/// Parses a blend mode name (as toString writes it); the error names the field's value.
Result<BlendMode> parseBlendMode(std::string_view name);

/// One input of a mosaic: a DEM file (any raster GDAL reads; its scale/offset and nodata are
/// honoured), or an in-memory raster when `raster` is set.
struct MosaicInput {
  std::string path;
  std::optional<Raster> raster;
  BlendMode mode = BlendMode::Replace;
  Resampling resampling = Resampling::Bilinear;
  int band = 1;  ///< 1-based band of the file
};

/// A named terrain layer: a raster on the target grid, NaN where no input has data.
struct Layer {
  std::string name;
  Raster raster;
};

/// Resamples one input onto `target` (metres; NaN where the input does not cover a cell).
/// Fails when the input cannot be read, has no georeference, or lives on another body.
Result<Raster> warpToGrid(const MosaicInput& input, const Georef& target);

/// Combines `src` into `layer` cell by cell with `mode` (sizes must match).
void blendInto(Grid<float>& layer, const Grid<float>& src, BlendMode mode);

/// Warps every input onto `target` and blends them in order into a layer named `name`.
Result<Layer> buildMosaic(const std::string& name, const Georef& target, std::span<const MosaicInput> inputs);

}  // namespace strata::gis
