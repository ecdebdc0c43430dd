#include <strata/scenario/report.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

#include <strata/core/files.hpp>
#include <strata/core/log.hpp>
#include <strata/core/process.hpp>
#include <strata/core/progress.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>

namespace strata::scenario {

/// The plotting scripts under scenario/plots, compiled in (StrataEmbedText.cmake): an installed
/// strata needs no file of the source tree.
std::string_view embeddedText(std::string_view name);

namespace fs = std::filesystem;
namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// User text (a scenario's name and description, inflow and material names) as report.md shows
// it: control characters written as visible \uXXXX escapes, so that none reaches a terminal or
// a viewer raw; in a table cell ('cell'), '|' escaped and line breaks as spaces too.
std::string userText(const std::string& text, bool cell = false) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (cell && (c == '\n' || c == '\t')) {
      out += ' ';
    } else if (cell && c == '|') {
      out += "\\|";
    } else if ((u < 0x20 && c != '\n' && c != '\t') || u == 0x7F) {
      char code[8];
      std::snprintf(code, sizeof code, "\\u%04X", unsigned(u));
      out += code;
    } else {
      out += c;
    }
  }
  return out;
}

std::string hours(double s) { return fmt("%.2f h", s / 3600.0); }

// "36.0586 N, 112.0030 W" for a cell centre.
std::string where(const gis::Georef& g, int x, int y) {
  auto ll = gis::pixelToLonLat(g, x + 0.5, y + 0.5);
  if (!ll) return "cell (" + std::to_string(x) + ", " + std::to_string(y) + ")";
  const double lon = ll->lonDeg > 180 ? ll->lonDeg - 360 : ll->lonDeg;
  return fmt("%.4f", std::abs(ll->latDeg)) + (ll->latDeg >= 0 ? " N, " : " S, ") + fmt("%.4f", std::abs(lon)) +
         (lon >= 0 ? " E" : " W");
}

// An area in the unit that fits: m² below 0.1 km², km² from there.
std::string areaText(double m2) { return m2 < 1e5 ? fmt("%.0f", m2) + " m²" : fmt("%.2f", m2 / 1e6) + " km²"; }

// The roughness: one n, or a map (a raster of n, or land-cover classes and their n).
// The model row's infiltration, as given (docs/sim-water.md, W11b).
std::string infiltrationText(const Scenario& s) {
  if (!s.water.infiltration) return "";
  const auto& f = *s.water.infiltration;
  const std::string rate = fmt("%.3g", f.rateMPerS * 3.6e6) + " mm/h";
  const std::string map = f.raster.empty()
                              ? std::string()
                              : " per cell from `" + userText(f.raster, true) + "` (" + rate + " where it has no data)";
  if (!f.greenAmpt) return ", infiltration at a constant loss of " + (map.empty() ? rate : "the rate" + map);
  return ", infiltration by Green-Ampt (Ks " + (map.empty() ? rate : map.substr(1)) + ", suction head " +
         fmt("%.3g", f.suctionM * 1e3) + " mm, moisture deficit " + fmt("%.3g", f.moistureDeficit) + ")";
}

std::string manningText(const Scenario& s) {
  const std::string n = fmt("%.3f", s.model.manningN) + " s/m^(1/3)";
  if (!s.model.manningRaster.empty()) {
    return "Manning n per cell from `" + userText(s.model.manningRaster, true) + "` (" + n + " where it has no data)";
  }
  if (!s.model.landCoverRaster.empty()) {
    std::string table;
    for (const auto& [code, v] : s.model.landCoverManning) {
      table += (table.empty() ? "" : ", ") + std::to_string(code) + ": " + fmt("%.3f", v);
    }
    return "Manning n per cell from the land cover `" + userText(s.model.landCoverRaster, true) + "` (class: n " +
           table + "; " + n + " where it has no data)";
  }
  return "Manning n = " + n;
}

// The gauges' and sections' peaks and volumes; their rows are in gauges.csv and sections.csv.
std::string probesSection(const RunSummary& sum, const ScenarioDomain& d, const fs::path& runDir) {
  std::string md = "## Gauges and sections\n\n";
  if (!sum.gauges.empty()) {
    md +=
        "Gauges (`gauges.csv`: depth, water level, speed and the bearing the water flows toward, every "
        "`probe_interval`; the peak is taken after every step, as the max_depth map):\n\n";
    md += "| gauge | where | peak depth | at |\n|---|---|---|---|\n";
    for (const auto& g : sum.gauges) {
      md += "| " + userText(g.name, true) + " | " + where(d.bed.georef, g.x, g.y) + " | " + fmt("%.3f", g.peak) +
            " m | " + (g.peakTimeS >= 0 ? hours(g.peakTimeS) : std::string("never wet")) + " |\n";
    }
    md += "\n";
  }
  if (!sum.sections.empty()) {
    md +=
        "Sections (`sections.csv`: discharge across the line, positive from its left to its right facing from its "
        "first point to its last, the volume so far and the mean water level along it). The discharge is summed "
        "after every step from the fluxes the solver applied, so the volume is the water that crossed:\n\n";
    md +=
        "| section | faces | peak discharge | at | net volume | left to right | right to left |\n"
        "|---|---|---|---|---|---|---|\n";
    for (const auto& c : sum.sections) {
      md += "| " + userText(c.name, true) + " | " + std::to_string(c.faces) + " | " + fmt("%.3g", c.peak) + " m³/s | " +
            (c.peakTimeS >= 0 ? hours(c.peakTimeS) : std::string("nothing crossed")) + " | " + volumeText(c.volumeM3) +
            " | " + volumeText(c.forwardM3) + " | " + volumeText(c.backM3) + " |\n";
    }
    md += "\n";
  }
  for (const char* p : {"gauges", "sections"}) {
    if (fs::exists(runDir / "plots" / (std::string(p) + ".png")))
      md += "![" + std::string(p) + "](plots/" + p + ".png)\n";
  }
  return md + "\n";
}

// Runs an embedded plotting script with Debian's Python (where python3-matplotlib is): the
// script on standard input, the paths as arguments (no shell: any file name works).
Status runPlotScript(const std::string& script, const std::vector<std::string>& args) {
  const std::string_view text = embeddedText(script);
  STRATA_CHECK(!text.empty()) << script << " is not embedded";
  std::vector<std::string> argv{"/usr/bin/python3", "-"};
  argv.insert(argv.end(), args.begin(), args.end());
  auto out = runProcess(argv, text);
  if (!out) return fail("report: " + script + ": " + out.message());
  return {};
}

}  // namespace

Result<std::vector<std::string>> writePlots(const fs::path& runDir, bool haveSeries) {
  std::error_code ec;
  fs::create_directories(runDir / "plots", ec);
  if (haveSeries) {
    STRATA_TRY_STATUS(runPlotScript("plot_series.py", {(runDir / "series.csv").string(), (runDir / "plots").string()}));
  }
  STRATA_TRY_STATUS(runPlotScript("plot_maps.py", {runDir.string()}));
  std::vector<std::string> files{"maps/elevation.tif"};
  for (const auto& e : fs::directory_iterator(runDir / "plots")) {
    if (e.path().extension() == ".png") files.push_back("plots/" + e.path().filename().string());
  }
  std::sort(files.begin() + 1, files.end());
  return files;
}

// Where the material went: a volume table per layer and the balance (docs/scenario.md, "Erosion
// outputs").
std::string materialSection(const MaterialBudget& b) {
  std::string md = "## Material\n\n";
  md += "| layer (bottom first) | material | at the start | at the end | change | exposed at the start / end |\n";
  md += "|---|---|---|---|---|---|\n";
  double exposedStart = 0;
  for (double a : b.exposedInitialM2) exposedStart += a;
  auto share = [&](double a) { return exposedStart > 0 ? fmt("%.1f%%", 100 * a / exposedStart) : std::string("-"); };
  for (size_t l = 0; l < b.layers.size(); ++l) {
    md += "| " + std::to_string(l + 1) + " | " + b.layers[l] + " | " + fmt("%.6g", b.initialM3[l]) + " m³ | " +
          fmt("%.6g", b.finalM3[l]) + " m³ | " + fmt("%+.6g", b.finalM3[l] - b.initialM3[l]) + " m³ | " +
          share(b.exposedInitialM2[l]) + " / " + share(b.exposedFinalM2[l]) + " |\n";
  }
  const double balance = b.balanceM3();
  md += "\n| balance | m³ |\n|---|---|\n";
  md += "| eroded (net cut, summed over the cells that lost material) | " + fmt("%.6g", b.erodedM3) + " |\n";
  md += "| deposited (net fill, summed over the cells that gained) | " + fmt("%.6g", b.depositedM3) + " |\n";
  md += "| suspended in the water at the end | " + fmt("%.6g", b.suspendedM3) + " |\n";
  md += "| carried out through open edges | " + fmt("%.6g", b.outflowM3) + " |\n";
  md += "| deposited + suspended + carried out − eroded (0 up to float rounding) | " + fmt("%.3g", balance) + " (" +
        fmt("%.2e", b.initialM3Total > 0 ? balance / b.initialM3Total : 0.0) + " of all material) |\n\n";
  md +=
      "Exposed: the topmost layer at least 1 cm thick (a thinner film does not hide what is under it). "
      "`maps/exposed_material.tif` holds the layer number − 1 of the exposed material (0 = layer 1); "
      "`maps/layer_K.tif` each layer's thickness at the end (m).\n\n";
  return md;
}

// The erosion model that ran and its constants (issue 30: the report names the law).
std::string erosionModelSection(const Scenario& s, const ScenarioDomain& d) {
  std::string md = "## Erosion model\n\n";
  if (s.erosion.law == sim::ErosionLaw::kShearStress) {
    md +=
        "Shear-stress law (docs/sim-erosion.md, E1-E3): the flow entrains the topmost layer at "
        "E = k_d (τ − τ_c) where the bed shear stress τ = ρ g n² |u|² / h^(1/3) exceeds the material's "
        "critical shear stress (Partheniades 1965; k_d and τ_c after Hanson and Simon 2001), and the load settles "
        "at D = w_s c with the settling velocity of the deposit layer's material (Hairsine and Rose 1992); "
        "Manning n = " +
        fmt("%.3f", s.model.manningN) + ". ";
  } else {
    md +=
        "Force-based capacity law of the seed systems (docs/sim-erosion.md, E1-E3; Stava et al. 2008): capacity "
        "C = Kc sin(tilt) |v| (1 − h / 1 m), Kc = " +
        fmt("%.3g", s.erosion.capacity) + " s, pick-up Ks = " + fmt("%.3g", s.erosion.erosionRate) +
        " /s, settling Kd = " + fmt("%.3g", s.erosion.depositionRate) +
        " /s: model constants for authoring terrain, not calibrated in physical units. ";
  }
  md += s.erosion.thermal ? "Dry slopes weather down to each material's talus angle at its weathering rate (E7); "
                            "banks fall into what the flow scours at their toe, at their friction angle and "
                            "cohesion, no more than the scour (E8).\n\n"
                          : "Weathering and bank failure are off ([erosion] thermal = false).\n\n";
  md +=
      "| layer | material | τ_c (Pa) | k_d (m/(s Pa)) | w_s (m/s) | friction angle | cohesion (Pa) | talus angle | "
      "weathering (1/s) | dissolution (1/s) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (size_t l = 0; l < d.input.materials.size(); ++l) {
    const auto& m = d.input.materials[l];
    md += "| " + std::to_string(l + 1) + " | " + userText(m.name, true) + " | " + fmt("%.3g", m.criticalShearPa) +
          " | " + fmt("%.3g", m.shearErodibility) + " | " + fmt("%.3g", m.settlingVelocityMS) + " | " +
          fmt("%.0f°", m.frictionAngleDeg) + " | " + fmt("%.3g", m.cohesionPa) + " | " + fmt("%.0f°", m.talusAngleDeg) +
          " | " + fmt("%.3g", m.weatheringRatePerS) + " | " + fmt("%.3g", m.dissolutionRate) + " |\n";
  }
  md += "\nThe top layer receives every deposit; the suspended load settles at its material's w_s.\n\n";
  return md;
}

Status writeReport(const fs::path& runDir, const ReportInput& in) {
  const auto& s = in.scenario;
  const auto& d = in.domain;
  const auto& sum = in.summary;
  const auto& g = d.bed.georef;
  std::string md;
  md += "# " + userText(s.name, true) + "\n\n";
  if (!s.description.empty()) md += userText(s.description) + "\n\n";
  {
    char date[64];
    const std::time_t now = std::time(nullptr);
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    md += "Run " + std::string(date) + " on " + in.backend + ": " + formatDuration(sum.simulatedS) + " simulated in " +
          formatDuration(sum.wallS) + " of wall time, " + std::to_string(sum.steps) + " steps";
    if (sum.steps > 0) md += fmt(" (mean step %.2f s)", sum.simulatedS / double(sum.steps));
    if (sum.spinUp.steps > 0) md += ", after the spin-up's " + std::to_string(sum.spinUp.steps) + " (in the wall time)";
    md += ".";
    if (!sum.completed) md += " **The run was stopped before the end; the numbers are those of the last interval.**";
    md += "\n\n";
  }

  // --- Scenario
  if (const auto warnings = runWarnings(in); !warnings.empty()) {
    md += "## Warnings\n\n";
    for (const auto& w : warnings) md += "- **" + w + "**\n";
    md += "\n";
  }
  md += "## Scenario\n\n";
  const auto [lo, hi] = d.bedRangeM;
  md += "| | |\n|---|---|\n";
  const std::string terrain =
      s.terrain.store.empty() ? "`" + s.terrain.dems.front() + "`" : "tile store `" + s.terrain.store + "`";
  std::string assigned;
  if (s.terrain.assignCrs) assigned += ", CRS assigned by the scenario";
  if (s.terrain.assignGeotransform) assigned += ", geotransform assigned by the scenario";
  md += "| terrain | " + terrain + " (" + g.crsName + (g.epsg ? ", EPSG:" + std::to_string(*g.epsg) : "") + ", " +
        g.body.name + assigned + ") |\n";
  // Cell widths follow the latitude on a geographic grid: the range over the rows is stated.
  const auto [narrowest, widest] = std::minmax_element(d.input.rowDxM.begin(), d.input.rowDxM.end());
  const std::string widths = *widest - *narrowest >= 0.5 ? " (widths " + fmt("%.0f", *narrowest) + " to " +
                                                               fmt("%.0f", *widest) + " m over the rows)"
                                                         : "";
  md += "| region | " + std::to_string(g.width) + " x " + std::to_string(g.height) + " cells of about " +
        fmt("%.0f", d.input.rowDxM[d.input.rowDxM.size() / 2]) + " x " + fmt("%.0f", d.input.dyM) + " m" + widths +
        ", " + fmt("%.0f", d.totalAreaM2 / 1e6) + " km², elevations " + fmt("%.0f", lo) + " to " + fmt("%.0f", hi) +
        " m |\n";
  md += std::string("| model | ") +
        (s.model.kind == sim::WaterModel::kFiniteVolume
             ? (s.model.inertial
                    ? (s.model.localSteps ? "flood mode (local-inertial shallow water, Bates et al. 2010, Manning "
                                            "friction; local time steps, W37)"
                                          : "flood mode (local-inertial shallow water, Bates et al. 2010, Manning "
                                            "friction)")
                    : "flood mode (finite-volume shallow water, Manning friction)")
             : "virtual pipes: an interactive authoring model without friction, whose depths and speeds depend on "
               "the pipe area and the time step and are not physical (kind = \"flood\" for analysis, "
               "docs/sim-water.md)") +
        ", " + manningText(s) + infiltrationText(s) + ", CFL " + fmt("%.2f", s.model.cfl) +
        (s.model.kind == sim::WaterModel::kFiniteVolume && !s.model.inertial
             ? (s.model.sharpSlopes ? ", MC slopes" : ", minmod slopes")
             : "") +
        " |\n";
  const char* edges[4] = {"west", "east", "south", "north"};
  std::string bounds;
  for (int e = 0; e < 4; ++e) {
    bounds += std::string(bounds.empty() ? "" : ", ") + edges[e] + " " +
              (s.model.boundaries[size_t(e)] == strata::scenario::Boundary::Open ? "open" : "closed");
  }
  md += "| edges | " + bounds + " |\n";
  if (d.breach.paths > 0) {
    md += "| breached | " + std::to_string(d.breach.paths) +
          " inflow path(s) to an open edge given the closest profile that never climbs ([terrain] breach_inflows): " +
          std::to_string(d.breach.cells) + " cells changed, cut by up to " + fmt("%.0f", d.breach.maxCutM) +
          " m and filled by up to " + fmt("%.0f", d.breach.maxFillM) + " m (" + volumeText(d.breach.cutM3) + " cut, " +
          volumeText(d.breach.fillM3) + " filled) |\n";
  }
  if (s.terrain.fillDepressions) {
    md += "| depressions filled | " + std::to_string(d.filled.cells) +
          " cells that drained to no open edge raised to their spill level ([terrain] fill_depressions), by up to " +
          fmt("%.0f", d.filled.maxM) + " m, " + volumeText(d.filled.volumeM3) + " in all |\n";
  }
  if (s.terrain.breachInflows || s.terrain.fillDepressions) {
    md +=
        "| where the DEM was changed | `maps/conditioning.tif`: the bed the model used less the DEM, cell by cell "
        "(cut < 0 < raised)" +
        std::string(fs::exists(runDir / "plots" / "conditioning.png") ? ", drawn in `plots/conditioning.png`" : "") +
        " |\n";
  }
  for (size_t l = 0; l < s.terrain.layers.size() && l < d.layerCellsTooSteep.size(); ++l) {
    if (!s.terrain.layers[l].atRest) continue;
    const size_t k = d.input.materials.size() - s.terrain.layers.size() + l;  // the scenario's layers are on top
    md += "| " + s.terrain.layers[l].material + " at rest | none on the " + std::to_string(d.layerCellsTooSteep[l]) +
          " cells whose ground is steeper than its " + fmt("%.0f", d.input.materials[k].talusAngleDeg) +
          "° angle of repose ([[terrain.layer]] at_rest) |\n";
  }
  if (d.voidCells > 0) {
    using V = decltype(s.terrain)::Voids;
    const char* what = s.terrain.voids == V::kFill    ? "filled from the cells around them (GDAL fill-nodata)"
                       : s.terrain.voids == V::kWalls ? "walls no water enters"
                                                      : "holes: water that reaches them leaves the region";
    md += "| voids | " + std::to_string(d.voidCells) + " cells without data in the source, " + what +
          " ([terrain] voids) |\n";
  }
  for (size_t i = 0; i < s.water.inflows.size(); ++i) {
    const auto& f = s.water.inflows[i];
    const double peak = f.hydrograph.maxOver(0, s.durationS);
    const auto& c = d.sources[i].cells.front();
    md += "| inflow \"" + userText(f.name, true) + "\" | at " + where(g, c.first, c.second) + ", peak " +
          fmt("%.0f", peak) + " m³/s, " + volumeText(f.hydrograph.integral(0, s.durationS)) + " in the run |\n";
  }
  if (const auto& u = in.summary.spinUp; u.seconds > 0) {
    const std::string tolerance = fmt("%g", 100 * u.toleranceRel) + "% of the base flow";
    std::string length = "run for a spin-up of " + formatDuration(u.seconds) + " before t = 0";
    if (u.steady) {
      length = "run until steady: " + formatDuration(u.seconds) + " before t = 0 (of at most " +
               formatDuration(u.longestS) + "; it ends once the stored water changes by less than " + tolerance +
               ", judged every " + formatDuration(u.longestS / 20) + " over the last " + formatDuration(u.windowS) +
               ")";
    } else if (u.toleranceRel > 0) {
      length += " (at most; **not steady**: the stored water still changed by more than " + tolerance +
                ": lengthen time.spin_up)";
    }
    md += "| base flow | " + fmt("%.0f", u.baseFlowM3S) + " m³/s (the inflows at t = 0), " + length + ", " +
          std::to_string(u.steps) + " steps: at t = 0 the region held " + volumeText(u.storedM3) + "; over the last " +
          formatDuration(u.windowS) + " of it " + fmt("%.0f", u.outflowM3S) +
          " m³/s left it and the stored water changed by " + fmt("%+.0f", u.storageRateM3S) +
          " m³/s. Every result below is of the run from t = 0: the river's water at t = 0 is the initial water, and "
          "cells wet at t = 0 count as flooded from the start |\n";
  }
  if (s.water.rain && s.water.rain->frames.empty()) {
    md += "| rain | " + fmt("%.1f", s.water.rain->rateMPerS * 3.6e6) + " mm/h |\n";
  } else if (s.water.rain) {
    const auto& fr = s.water.rain->frames;
    md +=
        "| rain | " + std::to_string(fr.size()) + " raster frame" + (fr.size() > 1 ? "s" : "") + " (mm/h), `" +
        userText(fr.front().raster, true) + "` at " + formatDuration(fr.front().timeS) +
        (fr.size() > 1 ? " to `" + userText(fr.back().raster, true) + "` at " + formatDuration(fr.back().timeS) : "") +
        ", falling until " + formatDuration(d.rainFramesEndS) + " |\n";
  }
  if (d.damBreakVolumeM3 > 0) md += "| dam break | " + volumeText(d.damBreakVolumeM3) + " released at t = 0 |\n";
  md += "| duration | " + formatDuration(s.durationS) + ", outputs every " + formatDuration(s.outputIntervalS) + " |\n";
  md += "| wet threshold | " + fmt("%.2f", s.outputs.wetThresholdM) + " m |\n\n";

  // --- Results
  md += "## What happened\n\n";
  if (sum.series.empty()) {
    md += "No interval finished.\n";
  } else {
    const auto& last = sum.series.back();
    const auto peakW = *std::max_element(sum.series.begin(), sum.series.end(),
                                         [](const auto& a, const auto& b) { return a.waterM3 < b.waterM3; });
    const auto peakA = *std::max_element(sum.series.begin(), sum.series.end(), [](const auto& a, const auto& b) {
      return a.floodedAreaKm2 < b.floodedAreaKm2;
    });
    const auto& f = in.flood;
    const double supplied = last.inflowM3 + last.rainM3 + d.damBreakVolumeM3 + sum.spinUp.storedM3;
    md += "| quantity | value |\n|---|---|\n";
    md += "| water that entered | " + volumeText(last.inflowM3 + last.rainM3) + " (inflow " +
          volumeText(last.inflowM3) + ", rain " + volumeText(last.rainM3) + ")" +
          (d.damBreakVolumeM3 > 0 ? " + dam " + volumeText(d.damBreakVolumeM3) : "") +
          (sum.spinUp.seconds > 0 ? ", after the " + volumeText(sum.spinUp.storedM3) + " of the base flow at t = 0"
                                  : "") +
          " |\n";
    md += "| most water in the region | " + volumeText(peakW.waterM3) + " at " + hours(peakW.timeS) + " |\n";
    md += "| largest flooded area | " + fmt("%.1f", peakA.floodedAreaKm2) + " km² at " + hours(peakA.timeS) + " (" +
          fmt("%.1f", 100 * peakA.floodedAreaKm2 * 1e6 / d.totalAreaM2) + "% of the region) |\n";
    md += "| area flooded at some time | " + areaText(f.everWetM2) + " |\n";
    if (f.everWetM2 > 0) {
      md += "| of which, by flood hazard to people (FD2321, " +
            std::string(hazardLandUseName(s.outputs.hazardLandUse)) + " debris factors) |";
      for (size_t k = 0; k < f.hazardClassM2.size(); ++k) {
        md += std::string(k ? ";" : "") + " " + std::string(kHazardClassNames[k]) + " " + areaText(f.hazardClassM2[k]);
      }
      md += " (rated from each cell's largest depth and largest speed: an upper bound) |\n";
    }
    md += "| deepest water | " + fmt("%.1f", f.deepest.value) + " m at " + where(g, f.deepest.x, f.deepest.y) + " |\n";
    md +=
        "| fastest water | " + fmt("%.1f", f.fastest.value) + " m/s at " + where(g, f.fastest.x, f.fastest.y) + " |\n";
    if (!d.sources.empty()) {
      md += "| farthest reach | " + fmt("%.1f", std::max(0.0, f.farthest.value) / 1e3) + " km (straight line) from \"" +
            d.sourceNames.front() + "\", at " + where(g, f.farthest.x, f.farthest.y) +
            (f.farthestArrivalS >= 0 ? ", reached at " + hours(f.farthestArrivalS) : "") + " |\n";
    }
    md += "| water that left through the edges | " + volumeText(last.outflowM3) +
          (supplied > 0 ? " (" + fmt("%.0f", 100 * last.outflowM3 / supplied) + "% of what entered" +
                              (sum.spinUp.seconds > 0 ? " or was there at t = 0)" : ")")
                        : "") +
          " |\n";
    if (s.water.infiltration) {
      md += "| water that soaked into the ground | " + volumeText(last.infiltrationM3) +
            (supplied > 0 ? " (" + fmt("%.0f", 100 * last.infiltrationM3 / supplied) + "% of what entered" +
                                (sum.spinUp.seconds > 0 ? " or was there at t = 0)" : ")")
                          : "") +
            " |\n";
    }
    md += "| water in the region at the end | " + volumeText(last.waterM3) + ", " + fmt("%.1f", last.floodedAreaKm2) +
          " km² flooded |\n";
    md += "| volume balance error at the end | " + fmt("%.2e", last.balanceErrorRel) +
          " (in − out − stored, relative to what entered) |\n";
    if (s.erosion.enabled) {
      md += "| ground eroded / deposited | " + fmt("%.0f", last.erodedM3) + " / " + fmt("%.0f", last.depositedM3) +
            " m³ |\n";
    }
    md += "\n";
  }

  if (!sum.gauges.empty() || !sum.sections.empty()) md += probesSection(sum, d, runDir);
  if (s.erosion.enabled) md += erosionModelSection(s, d);
  if (sum.material) md += materialSection(*sum.material);

  // --- Maps and plots
  md += "## Maps\n\nGeoTIFFs in the region's CRS (`maps/`), drawn over a hillshade:\n\n";
  for (const auto& m : s.outputs.maps) {
    if (fs::exists(runDir / "plots" / (m + ".png"))) md += "![" + m + "](plots/" + m + ".png)\n";
  }
  md += "\n## Time series\n\n`series.csv`, one row per output interval:\n\n";
  for (const char* p : {"water", "area", "balance", "sediment"}) {
    if (fs::exists(runDir / "plots" / (std::string(p) + ".png")))
      md += "![" + std::string(p) + "](plots/" + p + ".png)\n";
  }
  if (!in.pictures.empty()) {
    md += "\n## Pictures\n\n";
    for (const auto& p : in.pictures) {
      md += "![" + p + "](" + p + ")\n";
      if (p.find("max_depth") != std::string::npos && !in.maxDepthLegend.empty())
        md += "\n" + in.maxDepthLegend + "\n\n";
    }
  }
  md += "\n## Files\n\n";
  for (const auto& f : sum.files) md += "- `" + f + "`\n";
  return writeFileAtomic(runDir / "report.md", md);
}

std::vector<std::string> runWarnings(const ReportInput& in) {
  std::vector<std::string> out;
  const auto& f = in.flood;
  const auto& g = in.domain.bed.georef;
  if (f.waterAtEndM3 > 0 && f.pondedM3 > 0.2 * f.waterAtEndM3) {
    out.push_back(volumeText(f.pondedM3) + " (" + fmt("%.0f", 100 * f.pondedM3 / f.waterAtEndM3) +
                  "% of the water in the region at the end) stands in closed depressions of the bed, pits that "
                  "drain nowhere, up to " +
                  fmt("%.1f", f.deepestPonded.value) + " m deep at " + where(g, f.deepestPonded.x, f.deepestPonded.y) +
                  ". Where they are artefacts of the DEM (SRTM has them in narrow valleys and under voids), "
                  "`[terrain] fill_depressions = true` raises them to their spill level and `breach_inflows = true` "
                  "carves each inflow's path out (docs/scenario.md, \"Conditioning the DEM\").");
  }
  if (f.wetVoidCells > 0) {
    out.push_back("The flood reached " + std::to_string(f.wetVoidCells) + " of the " +
                  std::to_string(in.domain.voidCells) + " cells the DEM had no data for (" + areaText(f.wetVoidM2) +
                  "), whose ground was filled from the cells around them (`[terrain] voids = \"fill\"`): the water "
                  "there, up to " +
                  fmt("%.1f", f.deepestVoid.value) + " m deep at " + where(g, f.deepestVoid.x, f.deepestVoid.y) +
                  ", stands on ground the DEM does not have. Check those places against another source (a "
                  "void-filled DEM, a survey) before using depths, speeds or hazard there.");
  }
  if (f.fastest.value > 10.0) {
    // Next to an inflow (within 2 cells of one of its cells) the speed is the inflow line's doing.
    std::string why =
        "it usually comes from a step in the DEM (a void's edge, a dam, SRTM's stairs on steep slopes) or cells too "
        "coarse for the channel. Look at `maps/max_speed.tif` there before trusting speeds and hazard near it.";
    const auto& d = in.domain;
    for (size_t i = 0; i < d.sources.size() && i < d.sourceNames.size(); ++i) {
      const bool near = std::any_of(d.sources[i].cells.begin(), d.sources[i].cells.end(), [&](const auto& c) {
        return std::abs(c.first - f.fastest.x) <= 2 && std::abs(c.second - f.fastest.y) <= 2;
      });
      if (!near) continue;
      double peak = 0;
      for (const auto& sample : d.sources[i].dischargeM3S.samples()) peak = std::max(peak, sample[1]);
      why = "it is next to the inflow \"" + userText(d.sourceNames[i]) + "\", which puts up to " + fmt("%.0f", peak) +
            " m³/s into " + std::to_string(d.sources[i].cells.size()) +
            " cell(s): the speed there is set by how wide the inflow line is, not by the valley. A line across the "
            "whole channel's width (`line_lonlat`) spreads it as the river would arrive.";
      break;
    }
    out.push_back("The fastest water, " + fmt("%.1f", f.fastest.value) + " m/s at " +
                  where(g, f.fastest.x, f.fastest.y) + ", is faster than floods run but over steep chutes: " + why);
  }
  if (in.scenario.model.inertial && f.supercriticalM2 > 0) {
    out.push_back("The flow was supercritical on " + areaText(f.supercriticalM2) + " (Froude number up to at least " +
                  fmt("%.1f", f.froude.value) + ", at " + where(g, f.froude.x, f.froude.y) +
                  "): the local-inertial scheme leaves out advection and holds only for gently varying, subcritical "
                  "flow (de Almeida and Bates 2013). Its depths and speeds there and downstream are not reliable; "
                  "run it again with `[model] scheme = \"finite_volume\"` (docs/sim-water.md).");
  }
  return out;
}

std::string volumeText(double m3) {
  const double a = std::abs(m3);
  if (a < 1e4) return fmt("%.0f", m3) + " m³";
  if (a < 1e6) return fmt("%.1f", m3 / 1e3) + " thousand m³";
  return fmt("%.1f", m3 / 1e6) + " million m³";
}

}  // namespace strata::scenario
