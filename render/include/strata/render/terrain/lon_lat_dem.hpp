#pragma once
// Planetary mode needs lon/lat grids. A DEM in an equirectangular projection on a sphere (the
// LOLA LDEM: metres from a central meridian) already has cells along parallels and meridians;
// this re-expresses its geotransform in degrees.

#include <string>

#include <strata/core/result.hpp>
#include <strata/gis/raster.hpp>

namespace strata::render::terrain {

/// `dem` unchanged if geographic; an equirectangular-on-a-sphere DEM with its geotransform in
/// lon/lat degrees; otherwise an error naming `label`.
Result<gis::Raster> toLonLat(gis::Raster dem, const std::string& label);

}  // namespace strata::render::terrain
