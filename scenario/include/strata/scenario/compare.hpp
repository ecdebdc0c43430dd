#pragma once
// strata compare RUN_A RUN_B -o OUT: the "what changed" of a what-if. Two run folders of the same
// region (the same grid: size, geotransform and CRS) give OUT/maps/NAME_difference.tif = B - A
// for every map both have (with a diverging QGIS style beside it and a plot in OUT/plots/),
// and OUT/compare.md: the headline numbers of both runs side by side (from their series.csv and
// their gauges' and sections' rows) with the difference. Nothing in either run is written.

#include <filesystem>
#include <string>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::scenario {

struct CompareOptions {
  std::filesystem::path runA, runB, outDir;
  bool plots = true;
};

/// The files written, relative to outDir. Refused, naming the folder or map: a run folder
/// without a series, maps of different grids, no map in common, an outDir that exists and is not
/// empty.
Result<std::vector<std::string>> compareRuns(const CompareOptions& options);

}  // namespace strata::scenario
