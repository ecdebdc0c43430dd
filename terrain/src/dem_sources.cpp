#include <strata/terrain/dem_sources.hpp>

#include <memory>

#include <strata/gis/dem_io.hpp>

namespace strata::terrain {

WindowReader demReader(const std::string& path) {
  // Opened on the first window and kept open: neighbouring windows share its blocks.
  auto file = std::make_shared<std::optional<gis::DemFile>>();
  return [path, file](int x, int y, int w, int h) -> Result<gis::Grid<float>> {
    if (!*file) {
      gis::ReadOptions o;
      o.allowAllNoData = true;  // tiles outside a non-rectangular domain are expected
      STRATA_TRY(auto f, gis::DemFile::open(path, o));
      file->emplace(std::move(f));
    }
    STRATA_TRY(auto r, (*file)->read(gis::CellRect{x, y, w, h}));
    return std::move(r.values);
  };
}

Result<WindowReader> mosaicReader(std::vector<gis::MosaicInput> inputs, const gis::Georef& grid) {
  STRATA_TRY(auto reader, gis::MosaicReader::open(std::move(inputs), grid));
  auto shared = std::make_shared<gis::MosaicReader>(std::move(reader));
  return WindowReader([shared](int x, int y, int w, int h) { return shared->read(gis::CellRect{x, y, w, h}); });
}

}  // namespace strata::terrain
