#pragma once
// Test-only helpers of the procgen tests: DEM heights through gis::readDem and a hillshade PNG
// writer to look at generated terrain.
#include <filesystem>
#include <string>

#include <strata/gis/raster.hpp>

namespace strata::test {

/// The heights of a DEM (gis::readDem: metres, nodata as NaN); aborts the test run on failure.
gis::Grid<float> readDemForTest(const std::string& path);

/// Writes an 8-bit grey hillshade (sun from the north-west, 45 degrees up) of `heights` with
/// the given cell size to `png`; returns false when the file could not be written.
bool writeHillshadePng(const gis::Grid<float>& heights, double cellSizeM, const std::filesystem::path& png);

}  // namespace strata::test
