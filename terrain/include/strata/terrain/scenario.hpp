#pragma once
// A what-if scenario: the terrain, the region, the model, the water, the time and the outputs,
// read from a TOML file. Every dimensional value carries its unit ("6 h", "12 mm/h",
// "5000 m3/s"; a bare number is the SI unit: s, m, m/s, m3/s); a wrong unit, an unknown key or an
// inconsistent value is refused before any work with "file:line: key 'a.b': what is wrong".
// The format is documented in docs/scenario.md.

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>

namespace strata::terrain {

/// Where coordinates in the file are given: lon/lat degrees (WGS84 or the body's geographic
/// CRS), or x/y in the DEM's own CRS.
enum class CoordFrame { LonLat, DemCrs };

/// Points, a polyline or a polygon, as written in the file.
struct Place {
  CoordFrame frame = CoordFrame::LonLat;
  std::vector<std::array<double, 2>> points;
  int line = 0;     ///< line in the scenario file, for later messages
  std::string key;  ///< e.g. "water.inflow[0].at_lonlat"
};

/// Discharge over time, linearly interpolated, zero outside its span.
struct Hydrograph {
  std::vector<std::array<double, 2>> points;  ///< (seconds, m^3/s), times strictly increasing
  double at(double tSeconds) const;
  /// Volume (m^3) delivered between t0 and t1 (exact integral of the piecewise-linear curve).
  double volume(double t0, double t1) const;
};

struct Inflow {
  std::string name;
  Place place;  ///< one point (a spring) or a polyline (an inflow line)
  Hydrograph hydrograph;
};

struct Rain {
  double rateMPerS = 0;          ///< uniform rate
  std::string raster;            ///< optional raster of rate multipliers (path)
  double startS = 0, endS = -1;  ///< endS < 0: until the end
};

/// A volume of water standing behind a (removed) dam at t = 0.
struct DamBreak {
  Place polygon;
  double surfaceElevationM = 0;  ///< water surface inside the polygon
};

/// A fixed water level (a Dirichlet condition, docs/sim-water.md W26): the cells of a line or a
/// polygon are held at depth max(0, stage(t) - bed).
struct Level {
  std::string name;
  Place place;                               ///< a polyline or a polygon
  bool polygon = false;                      ///< place is a polygon (cells whose centre is inside), else a line
  std::vector<std::array<double, 2>> stage;  ///< (seconds, water surface elevation m), times strictly increasing
  int stageLine = 0;                         ///< line of `stage` in the file, for later messages
};

enum class WaterModel { Pipe, Flood };
enum class Boundary { Closed, Open };

struct LayerSpec {
  std::string material;   ///< a name from the material table
  double thicknessM = 0;  ///< uniform thickness, or
  std::string raster;     ///< a thickness raster
};

struct Scenario {
  std::filesystem::path file;  ///< the scenario file; relative paths inside are relative to it
  std::string name, description;

  struct {
    std::vector<std::string> dems;  ///< resolved paths (mosaicked in order)
    std::string store;
    std::vector<LayerSpec> layers;  ///< loose material on top of the bedrock DEM, bottom first
  } terrain;

  struct {
    enum Kind { Whole, BBox, Polygon } kind = Whole;
    Place place;           ///< BBox: two points (west-south, east-north); Polygon: the ring
    double cellSizeM = 0;  ///< 0: the DEM's own resolution
  } region;

  struct {
    WaterModel kind = WaterModel::Flood;
    double manningN = 0.035;   ///< s/m^(1/3)
    double cfl = 0.45;         ///< flood mode needs <= 0.5 (positivity of the finite-volume scheme)
    double maxStepS = 30.0;    ///< cap on the adaptive step (s); see docs/scenario.md
    bool sharpSlopes = false;  ///< flood mode: MC slopes instead of minmod (W21); see docs/sim-water.md
    std::array<Boundary, 4> boundaries{Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open};  ///< W E S N
  } model;

  struct {
    bool enabled = false;
    double capacity = 0.05, erosionRate = 0.01, depositionRate = 0.01, dissolutionRate = 0.0;
    bool thermal = true;
  } erosion;

  struct {
    std::vector<Inflow> inflows;
    std::optional<Rain> rain;
    std::vector<DamBreak> damBreaks;
    std::vector<Level> levels;
    double evaporationMPerS = 0;
  } water;

  double durationS = 0;
  double outputIntervalS = 0;

  struct {
    std::vector<std::string> maps{"max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"};
    double wetThresholdM = 0.05;  ///< depth above which a cell counts as flooded
    bool pictures = true;
    bool plots = true;
  } outputs;
};

/// Reads and checks a scenario file (syntax, keys, units, internal consistency). Checks that
/// need the terrain (region inside the DEM, sources inside the region) come later, once it is read.
Result<Scenario> loadScenario(const std::filesystem::path& file);
/// The same from text; `fileName` is used in messages and to resolve relative paths.
Result<Scenario> parseScenario(std::string_view text, const std::filesystem::path& fileName);

/// "6 h" -> 21600. `dimension` is "time", "length", "rate" (m/s), "discharge" (m3/s) or "speed".
Result<double> parseQuantity(std::string_view text, std::string_view dimension);

/// All output map names the runner knows.
const std::vector<std::string>& knownOutputMaps();

}  // namespace strata::terrain
