#include "styles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <strata/core/files.hpp>
#include <strata/gis/dem_io.hpp>
#include <strata/scenario/hazard.hpp>

#include "pieces.hpp"

namespace strata::scenario::detail {
namespace {

struct Stop {
  double at;  // 0..1 along the range (or a value, for discrete classes)
  const char* colour;
  const char* label = nullptr;
};

std::string number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string header() {
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
         "<qgis version=\"3.22.16\" styleCategories=\"Symbology\">\n";
}

// A singlebandpseudocolor renderer: INTERPOLATED stops over [low, high] (clip: values outside
// are not drawn), or DISCRETE classes whose `at` are upper bounds.
std::string pseudocolor(double low, double high, const std::vector<Stop>& stops, bool discrete, bool clip) {
  std::string items;
  for (const auto& s : stops) {
    const double v = discrete ? s.at : low + s.at * (high - low);
    const std::string value = std::isinf(v) ? "inf" : number(v);
    items += "          <item alpha=\"255\" color=\"" + std::string(s.colour) + "\" value=\"" + value + "\" label=\"" +
             (s.label ? std::string(s.label) : number(v)) + "\"/>\n";
  }
  return header() +
         "  <pipe>\n"
         "    <rasterrenderer type=\"singlebandpseudocolor\" band=\"1\" opacity=\"1\" alphaBand=\"-1\" "
         "classificationMin=\"" +
         number(low) + "\" classificationMax=\"" + number(high) +
         "\" nodataColor=\"\">\n"
         "      <rasterTransparency/>\n"
         "      <minMaxOrigin><limits>None</limits><extent>WholeRaster</extent><statAccuracy>Estimated</statAccuracy>"
         "<cumulativeCutLower>0.02</cumulativeCutLower><cumulativeCutUpper>0.98</cumulativeCutUpper>"
         "<stdDevFactor>2</stdDevFactor></minMaxOrigin>\n"
         "      <rastershader>\n"
         "        <colorrampshader colorRampType=\"" +
         (discrete ? "DISCRETE" : "INTERPOLATED") + "\" classificationMode=\"" + (discrete ? "2" : "1") + "\" clip=\"" +
         (clip ? "1" : "0") + "\" minimumValue=\"" + number(low) + "\" maximumValue=\"" + number(high) +
         "\" labelPrecision=\"2\">\n" + items +
         "        </colorrampshader>\n"
         "      </rastershader>\n"
         "    </rasterrenderer>\n"
         "    <brightnesscontrast brightness=\"0\" contrast=\"0\" gamma=\"1\"/>\n"
         "    <huesaturation saturation=\"0\" colorizeOn=\"0\" colorizeRed=\"255\" colorizeGreen=\"128\" "
         "colorizeBlue=\"128\" colorizeStrength=\"100\" grayscaleMode=\"0\"/>\n"
         "    <rasterresampler maxOversampling=\"2\"/>\n"
         "  </pipe>\n"
         "  <blendMode>0</blendMode>\n"
         "</qgis>\n";
}

// ColorBrewer's Blues, YlOrRd, RdBu; matplotlib's viridis; a terrain ramp.
const std::vector<Stop> kBlues{{0, "#c6dbef"}, {0.25, "#6baed6"}, {0.5, "#2171b5"}, {0.75, "#08519c"}, {1, "#08306b"}};
const std::vector<Stop> kHeat{{0, "#ffffb2"}, {0.25, "#fecc5c"}, {0.5, "#fd8d3c"}, {0.75, "#f03b20"}, {1, "#bd0026"}};
const std::vector<Stop> kViridis{
    {0, "#440154"}, {0.25, "#3b528b"}, {0.5, "#21918c"}, {0.75, "#5ec962"}, {1, "#fde725"}};
const std::vector<Stop> kTerrain{{0, "#1a9641"}, {0.3, "#a6d96a"}, {0.55, "#ffffbf"}, {0.8, "#a6611a"}, {1, "#f5f5f5"}};
const std::vector<Stop> kCutFill{
    {0, "#b2182b"}, {0.25, "#ef8a62"}, {0.5, "#f7f7f7"}, {0.75, "#67a9cf"}, {1, "#2166ac"}};

}  // namespace

std::string rasterStyle(const std::string& name, double low, double high, double wetThresholdM) {
  if (!(high > low)) high = low + 1;  // a constant map still gets a ramp
  if (name == "hazard_rating") {
    static const std::string labels[4] = {std::string(kHazardClassNames[0]), std::string(kHazardClassNames[1]),
                                          std::string(kHazardClassNames[2]), std::string(kHazardClassNames[3])};
    return pseudocolor(0, 3,
                       {{kHazardClassBounds[0], "#fee08b", labels[0].c_str()},
                        {kHazardClassBounds[1], "#fdae61", labels[1].c_str()},
                        {kHazardClassBounds[2], "#f46d43", labels[2].c_str()},
                        {INFINITY, "#a50026", labels[3].c_str()}},
                       true, false);
  }
  if (name == "max_depth" || name == "final_depth") {
    // From the wet threshold: shallower water is not drawn, a one-cell flood still shows.
    return pseudocolor(wetThresholdM, std::max(high, 2 * wetThresholdM), kBlues, false, true);
  }
  if (name == "max_speed") return pseudocolor(0, high, kHeat, false, false);
  if (name == "arrival_time" || name == "inundation_duration") return pseudocolor(0, high, kViridis, false, false);
  if (name == "elevation") return pseudocolor(low, high, kTerrain, false, false);
  if (name == "terrain_change" || name == "conditioning") {
    const double a = std::max({std::abs(low), std::abs(high), 1e-3});
    return pseudocolor(-a, a, kCutFill, false, false);
  }
  return pseudocolor(low, high, kViridis, false, false);
}

std::string outlineStyle() {
  return header() +
         "  <renderer-v2 type=\"singleSymbol\" forceraster=\"0\" symbollevels=\"0\" enableorderby=\"0\">\n"
         "    <symbols>\n"
         "      <symbol type=\"fill\" name=\"0\" alpha=\"1\" clip_to_extent=\"1\" force_rhr=\"0\">\n"
         "        <layer class=\"SimpleFill\" enabled=\"1\" locked=\"0\" pass=\"0\">\n"
         "          <Option type=\"Map\">\n"
         "            <Option type=\"QString\" name=\"color\" value=\"33,113,181,90\"/>\n"
         "            <Option type=\"QString\" name=\"outline_color\" value=\"8,48,107,255\"/>\n"
         "            <Option type=\"QString\" name=\"outline_style\" value=\"solid\"/>\n"
         "            <Option type=\"QString\" name=\"outline_width\" value=\"0.4\"/>\n"
         "            <Option type=\"QString\" name=\"outline_width_unit\" value=\"MM\"/>\n"
         "            <Option type=\"QString\" name=\"style\" value=\"solid\"/>\n"
         "          </Option>\n"
         "        </layer>\n"
         "      </symbol>\n"
         "    </symbols>\n"
         "  </renderer-v2>\n"
         "  <blendMode>0</blendMode>\n"
         "</qgis>\n";
}

Result<std::vector<std::string>> writeMapStyles(const std::filesystem::path& runDir,
                                                const std::vector<std::string>& maps, double wetThresholdM) {
  namespace fs = std::filesystem;
  std::vector<std::string> written;
  for (const auto& rel : maps) {
    const fs::path map = runDir / rel;
    const std::string name = map.stem().string();
    const std::string style = fs::path(rel).replace_extension(".qml").string();
    if (map.extension() == ".gpkg") {
      STRATA_TRY_STATUS(writeFileAtomic(runDir / style, outlineStyle()));
      written.push_back(style);
      continue;
    }
    // The range from at most ~4 million of its cells (every k-th of each row and column).
    STRATA_TRY(const auto info, gis::probeDem(map.string()));
    const double cells = double(info.georef.width) * double(info.georef.height);
    STRATA_TRY(const auto probe, readStrided(map, std::max(1, int(std::ceil(std::sqrt(cells / 4e6))))));
    double low = INFINITY, high = -INFINITY;
    for (float v : probe.values.data) {
      if (std::isfinite(v)) low = std::min(low, double(v)), high = std::max(high, double(v));
    }
    if (!std::isfinite(low)) low = 0, high = 1;
    STRATA_TRY_STATUS(writeFileAtomic(
        runDir / style, rasterStyle(name.starts_with("layer_") ? "layer" : name, low, high, wetThresholdM)));
    written.push_back(style);
  }
  return written;
}

}  // namespace strata::scenario::detail
