#pragma once
// Test-only helpers of the procgen tests: a plain GDAL DEM reader (until gis::readDem is on
// main) and a hillshade PNG writer to look at generated terrain.
#include <filesystem>
#include <string>

#include <strata/gis/raster.hpp>

namespace strata::test {

/// <STRATA_DATA_DIR>/<relative>: the shared real DEMs (test::dataPath lacks the compiled-in
/// folder in strata_test_main, so it only works from the project root).
std::string procgenDataPath(const std::string& relative);

/// Band 1 of a raster as float metres, nodata as NaN; aborts the test run on failure.
gis::Grid<float> readDemForTest(const std::string& path);

/// Writes an 8-bit grey hillshade (sun from the north-west, 45 degrees up) of `heights` with
/// the given cell size to `png`; returns false when the file could not be written.
bool writeHillshadePng(const gis::Grid<float>& heights, double cellSizeM, const std::filesystem::path& png);

}  // namespace strata::test
