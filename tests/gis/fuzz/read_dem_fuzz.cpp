// libFuzzer target over Strata's DEM reading path: the input bytes become a file in GDAL's
// /vsimem/ (no temporary files) and go through probeDem, readDem (whole and windowed) and
// the per-cell areas of what was read. Built and run by scripts/fuzz.sh, not by CMake.
// Only GDAL's GTiff driver stays registered: the target is our handling of what a TIFF can
// claim (sizes, types, nodata, georeference), not GDAL's other 150 drivers.
#include <cpl_conv.h>
#include <cpl_vsi.h>
#include <gdal_priv.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <strata/gis/dem_io.hpp>
#include <strata/gis/geodesy.hpp>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  CPLSetConfigOption("GDAL_PAM_ENABLED", "NO");  // no .aux.xml side files
  CPLSetConfigOption("CPL_DEBUG", "OFF");
  // Registers GDAL's drivers through the library's own call_once (a second GDALAllRegister after
  // drivers were destroyed crashes in GDAL 3.6), then keeps only GTiff and MEM.
  (void)strata::gis::probeDem("/vsimem/strata_fuzz_init.tif");
  GDALDriverManager* dm = GetGDALDriverManager();
  for (int i = dm->GetDriverCount() - 1; i >= 0; --i) {
    GDALDriver* d = dm->GetDriver(i);
    const std::string name = d->GetDescription();
    // Deregistered but kept alive and reachable from a static pointer (so LeakSanitizer does
    // not report them): destroying drivers crashes GDAL 3.6 later.
    static auto* parked = new std::vector<GDALDriver*>;
    if (name != "GTiff" && name != "MEM") {
      dm->DeregisterDriver(d);
      parked->push_back(d);
    }
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/vsimem/strata_fuzz.tif";
  VSILFILE* f = VSIFileFromMemBuffer(path.c_str(), const_cast<GByte*>(data), vsi_l_offset(size), FALSE);
  if (!f) return 0;
  VSIFCloseL(f);
  strata::gis::ReadOptions o;
  o.maxBytes = std::size_t(64) << 20;  // the fuzzer's memory limit, not the library default
  o.allowAllNoData = true;
  auto info = strata::gis::probeDem(path, o);
  if (info.ok()) {
    auto r = strata::gis::readDem(path, o);
    if (r.ok() && r->values.size() <= 4096) {
      auto areas = strata::gis::cellAreasM2(r->georef);
      (void)areas;
    }
    const auto& g = info->georef;
    o.window = strata::gis::CellRect{g.width / 3, g.height / 3, g.width / 2 + 1, g.height / 2 + 1};
    auto w = strata::gis::readDem(path, o);
    (void)w;
  }
  VSIUnlink(path.c_str());
  return 0;
}
