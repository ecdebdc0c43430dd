#pragma once
// QGIS layer styles beside a run's maps: maps/NAME.qml next to maps/NAME.tif (and
// maps/flood_outline.qml next to the GeoPackage), which QGIS applies when the file is added, so
// that dragging the run folder into QGIS shows each map with a ramp made for it: depths from the
// wet threshold in blues, speeds in heat colours, times in viridis, the hazard rating in FD2321's
// four classes, the bed as terrain, a cut and fill diverging around 0.

#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::scenario::detail {

/// The .qml of a single-band raster map `name` (a map name or "elevation") with values in
/// [low, high]; `wetThresholdM` is where depth ramps start.
std::string rasterStyle(const std::string& name, double low, double high, double wetThresholdM);
/// The .qml of the flood outline's polygons.
std::string outlineStyle();

/// Writes a style beside each of `maps` (the run's map files, relative to `runDir`: maps/NAME.tif,
/// the raster's range read from it, or maps/flood_outline.gpkg), returning the files written
/// (relative to the run folder). Nothing else in the folder is read.
Result<std::vector<std::string>> writeMapStyles(const std::filesystem::path& runDir,
                                                const std::vector<std::string>& maps, double wetThresholdM);

}  // namespace strata::scenario::detail
