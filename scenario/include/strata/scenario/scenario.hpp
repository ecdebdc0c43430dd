#pragma once
// A what-if scenario: the terrain, the region, the model, the water, the time and the outputs,
// read from a TOML file. Every dimensional value carries its unit ("6 h", "12 mm/h",
// "5000 m3/s"; a bare number is the SI unit: s, m, m/s, m3/s); a wrong unit, an unknown key or an
// inconsistent value is refused before any work with "file:line: key 'a.b': what is wrong".
// The format is documented in docs/scenario.md.

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <strata/core/result.hpp>
#include <strata/core/time_series.hpp>
#include <strata/scenario/hazard.hpp>
#include <strata/sim/params.hpp>

namespace strata::scenario {

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

struct Inflow {
  std::string name;
  Place place;            ///< one point (a spring) or a polyline (an inflow line)
  TimeSeries hydrograph;  ///< discharge (m^3/s) over time (s)
};

struct Rain {
  double rateMPerS = 0;          ///< uniform rate
  std::string raster;            ///< optional raster of rate multipliers (path)
  double startS = 0, endS = -1;  ///< endS < 0: until the end
  /// A raster series instead (radar frames): each frame's rain (mm/h per cell) falls from its
  /// time until the next frame's, the last one's until endS (or the run's end).
  struct Frame {
    double timeS = 0;
    std::string raster;  ///< resolved path
  };
  std::vector<Frame> frames;
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
  Place place;           ///< a polyline or a polygon
  bool polygon = false;  ///< place is a polygon (cells whose centre is inside), else a line
  TimeSeries stage;      ///< water surface elevation (m) over time (s)
  int stageLine = 0;     ///< line of `stage` in the file, for later messages
};

/// A gauge: depth, water level, speed and direction at a point, sampled through the run.
struct Gauge {
  std::string name;
  Place place;  ///< one point
};

/// A cross-section: the discharge across a polyline (signed: positive from its left to its right,
/// facing from its first point to its last) and the mean water level along it.
struct Section {
  std::string name;
  Place place;  ///< a polyline of at least two points
};

enum class Boundary { Closed, Open };

/// What runs the simulation: the GL backend on a hardware GPU and the CPU backend otherwise
/// (auto), or one of them by name.
enum class Backend { kAuto, kCpu, kGpu };

struct LayerSpec {
  std::string material;   ///< a name from the material table
  double thicknessM = 0;  ///< uniform thickness, or
  std::string raster;     ///< a thickness raster
  /// Only where it can rest: none on cells whose ground drops to a neighbour more steeply than
  /// the material's angle of repose (thermal weathering would shed it at once).
  bool atRest = false;
};

struct Scenario {
  std::filesystem::path file;  ///< the scenario file; relative paths inside are relative to it
  /// The TOML text it was read from (parseScenario, which every run's scenario comes through): a
  /// run writes it to its folder as scenario.toml and ties its checkpoints to it. A scenario
  /// given as text (the Python module's dicts) has no file of its own to copy.
  std::string text;
  std::string name, description;
  /// The line of every key read ("region.cell_size", "water.inflow[0].hydrograph"; a table's
  /// own name, e.g. "region", for the table), for messages of checks that come later.
  std::map<std::string, int> keyLines;

  /// "file:line: key 'k': " (the line where `key` is written; without it when not written), the
  /// start of every message about a key.
  std::string at(const std::string& key) const;

  struct {
    std::vector<std::string> dems;  ///< resolved paths (mosaicked in order)
    /// A CRS (EPSG:n, WKT or PROJ text) and a geotransform (GDAL's six coefficients) for DEMs that
    /// lack their own (a lidar tile without a .prj); each fills in only what a DEM is missing.
    std::optional<std::string> assignCrs;
    std::optional<std::array<double, 6>> assignGeotransform;
    std::string store;
    std::vector<LayerSpec> layers;  ///< loose material on top of the bedrock DEM, bottom first
    /// Carve each inflow's least-barrier path to an open edge (docs/scenario.md, "Breaching").
    bool breachInflows = false;
    /// Raise every cell that does not drain to an open edge to its spill level (docs/scenario.md).
    bool fillDepressions = false;
    /// What becomes of the region's cells without data (voids, e.g. SRTM's on steep slopes):
    /// refused (the default), filled from the cells around them (GDAL's fill-nodata), walls, or
    /// holes that take out all water that reaches them.
    enum class Voids { kRefuse, kFill, kWalls, kHoles } voids = Voids::kRefuse;
  } terrain;

  struct {
    enum Kind { Whole, BBox, Polygon } kind = Whole;
    Place place;           ///< BBox: two points (west-south, east-north); Polygon: the ring
    double cellSizeM = 0;  ///< 0: the DEM's own resolution
  } region;

  struct {
    sim::WaterModel kind = sim::WaterModel::kFiniteVolume;
    Backend backend = Backend::kAuto;
    double manningN = 0.035;  ///< s/m^(1/3); where a roughness map has no data too
    /// A roughness map: Manning's n per cell from a raster (bilinear), or from a land-cover
    /// raster's classes (nearest) through a table of n per class. Empty: manningN everywhere.
    std::string manningRaster;
    std::string landCoverRaster;
    std::map<long long, double> landCoverManning;  ///< class code -> n
    /// Flood mode's scheme: the local-inertial one (W30-W33) instead of finite volumes.
    bool inertial = false;
    /// Local time steps (W37): the local-inertial scheme's blocks step as their own CFL bound
    /// allows, on the CPU backend in one process.
    bool localSteps = false;
    double cfl = 0.45;         ///< finite volumes need <= 0.5 (positivity); the local-inertial default is 0.7
    double maxStepS = 30.0;    ///< cap on the adaptive step (s); see docs/scenario.md
    bool sharpSlopes = false;  ///< flood mode: MC slopes instead of minmod (W21); see docs/sim-water.md
    std::array<Boundary, 4> boundaries{Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open};  ///< W E S N
  } model;

  struct {
    bool enabled = false;
    /// E1-E3 (docs/sim-erosion.md): the materials' shear-stress constants, or the force-based
    /// law's model constants below.
    sim::ErosionLaw law = sim::ErosionLaw::kShearStress;
    double capacity = 0.05, erosionRate = 0.01, depositionRate = 0.01;  ///< the force-based law's Kc, Ks, Kd
    bool thermal = true;
  } erosion;

  /// [materials.NAME]: a material's constants changed for this run (docs/scenario.md); unset
  /// fields keep the store's or the default's.
  struct MaterialChange {
    std::string name;
    std::optional<double> criticalShearPa, shearErodibility, settlingVelocityMS, frictionAngleDeg, cohesionPa,
        talusAngleDeg, weatheringRatePerS, dissolutionRate, erodibility;
  };
  std::vector<MaterialChange> materials;

  /// [water.infiltration]: water lost to the soil (W11b): a constant loss at `rateMPerS`, or
  /// Green-Ampt with Ks = rateMPerS and suction head x moisture deficit; `raster` gives the rate
  /// or Ks per cell (mm/h; no data takes rateMPerS).
  struct Infiltration {
    bool greenAmpt = false;
    double rateMPerS = 0;        ///< constant: the loss rate; Green-Ampt: Ks (m/s)
    double suctionM = 0;         ///< Green-Ampt: wetting-front suction head psi (m)
    double moistureDeficit = 0;  ///< Green-Ampt: porosity - initial water content (0..1)
    std::string raster;
  };

  struct {
    std::vector<Inflow> inflows;
    std::optional<Rain> rain;
    std::optional<Infiltration> infiltration;
    std::vector<DamBreak> damBreaks;
    std::vector<Level> levels;
    double evaporationMPerS = 0;
  } water;

  double durationS = 0;
  double outputIntervalS = 0;
  /// Time run before t = 0 with every inflow and level held at its t = 0 value and no rain (a
  /// river's base flow settling into its bed); the outputs and the balance start at t = 0.
  double spinUpS = 0;
  /// > 0: the spin-up ends early, at a twentieth of spinUpS, once the stored water changed by
  /// less than this fraction of the base flow over its last tenth (steady); 0: it runs spinUpS.
  double spinUpTolerance = 0;

  struct {
    std::vector<std::string> maps{"max_depth",   "max_speed",     "arrival_time", "inundation_duration",
                                  "final_depth", "hazard_rating", "flood_outline"};
    /// The land use whose debris factor the hazard rating takes (hazard.hpp).
    HazardLandUse hazardLandUse = HazardLandUse::kUrban;
    double wetThresholdM = 0.05;  ///< depth above which a cell counts as flooded
    bool pictures = true;
    bool plots = true;
    std::vector<Gauge> gauges;      ///< [[outputs.gauge]]
    std::vector<Section> sections;  ///< [[outputs.section]]
    double probeIntervalS = 60;     ///< how often gauges and sections are written (s)
  } outputs;
};

/// At most this many output intervals (each writes the maps, the series and a checkpoint).
inline constexpr long long kMaxOutputIntervals = 100000;

/// Reads and checks a scenario file (syntax, keys, units, internal consistency). Checks that
/// need the terrain (region inside the DEM, sources inside the region) come later, once it is read.
Result<Scenario> loadScenario(const std::filesystem::path& file);
/// The same from text; `fileName` is used in messages and to resolve relative paths.
Result<Scenario> parseScenario(std::string_view text, const std::filesystem::path& fileName);

/// Every problem of a scenario's text, not only the first: what `strata check SCENARIO` prints.
struct ScenarioCheck {
  struct Problem {
    int line = 0;         ///< 0: the whole file
    std::string key;      ///< "" for the whole file
    std::string message;  ///< "file:line: key 'k': what is wrong", as loadScenario words it
  };
  std::vector<Problem> problems;  ///< in the order found (checkScenarioFile sorts them by line)
  /// The scenario as read once every problem's key was set aside (a refused value replaced by a
  /// valid stand-in or removed): for the checks that follow (raster paths); none when the file's
  /// syntax or a whole-file check failed.
  std::optional<Scenario> scenario;
  bool hasProblem(const std::string& key) const;
};

/// Reads `text` as parseScenario does, but on: each problem's key is set aside (an unknown key
/// that is a near miss of a missing allowed one, such as "duraton", renamed to it; a refused
/// required value replaced by a valid stand-in; anything else removed) and the reading goes on,
/// so that one pass finds every problem of the file; a problem that only follows from one found
/// (its key's value missing once removed) is not repeated. Whole-file checks (no key) are
/// reported only when nothing else is wrong.
ScenarioCheck checkScenarioText(std::string_view text, const std::filesystem::path& fileName);

/// `strata check SCENARIO`: checkScenarioText on the file, then every raster it names (DEMs, layer
/// and rain rasters; a store's manifest) opened as the run would, each problem "file:line: key
/// 'k': path: what is wrong"; all of them sorted by line. Empty: the file would run (as far as
/// anything short of building the domain can tell).
std::vector<std::string> checkScenarioFile(const std::filesystem::path& file);

/// "6 h" -> 21600. `dimension` is "time", "length", "rate" (m/s), "discharge" (m3/s), "speed" or
/// "stress" (Pa).
Result<double> parseQuantity(std::string_view text, std::string_view dimension);

/// "auto", "cpu" or "gpu" (the [model] backend key and the --backend option).
Result<Backend> parseBackend(std::string_view name);

/// `text` with its control characters escaped ("\\n", "\\x01"): user text quoted in a message
/// keeps it one line and cannot drive a terminal.
std::string oneLine(std::string_view text);

/// All output map names the runner knows.
const std::vector<std::string>& knownOutputMaps();
/// The maps only an erosion run has (a subset of knownOutputMaps): asked for by default when
/// erosion is on and [outputs] lists no maps.
const std::vector<std::string>& erosionOutputMaps();

}  // namespace strata::scenario
