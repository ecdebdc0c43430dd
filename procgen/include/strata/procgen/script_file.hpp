#pragma once
// Generation script files (TOML, docs/procgen.md "Script files"): one or more material layers,
// each a GLSL expression of position (height form) or of position and level (level form), the
// input DEMs, the pyramid depth and an optional georeference for the outputs.

#include <optional>
#include <string>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/procgen/generator.hpp>

namespace strata::procgen {

/// Where the output grid lies: EPSG code, top-left corner and square cell size (CRS units).
struct OutputGeoref {
  int epsg = 0;
  double originX = 0, originY = 0;  ///< top-left corner of the top-left cell
  double cellSize = 1;              ///< > 0
};

/// One material layer: its name (the output file stem) and its script.
struct LayerScript {
  std::string name;
  UserScript script;
  int matchDem = -1;         ///< histogram-match detail bands to this DEM (-1: off)
  bool matchCoarse = false;  ///< also match the coarse band
};

/// A parsed script file.
struct ScriptFile {
  std::vector<LayerScript> layers;
  std::vector<std::string> demPaths;  ///< resolved against the script's folder
  int levels = 6;
  procgen::Wavelet wavelet = procgen::Wavelet::Cdf53;  ///< `wavelet = "cdf53" | "cdf97"`
  std::optional<OutputGeoref> georef;
};

/// Reads and checks a script file; errors name the file and the field.
Result<ScriptFile> loadScriptFile(const std::string& path);

}  // namespace strata::procgen
