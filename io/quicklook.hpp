#pragma once
// quicklook.png: a picture of a run for people who would rather look than read. The DEM's
// hillshade (north up), one raster on top (reach probability, else the maximum energy, speed or
// passages; yellow = low, dark red = the largest value in the raster, transparent where no rock
// passed; energy on a log scale) and the paths of a sample of rocks in blue.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "ensemble/rasters.hpp"
#include "solver/terrain.hpp"

namespace talus::io {

// The layer the quick-look shows: the first of reach_probability, energy_max, speed_max, passages
// in `layers`, or nullptr.
const ensemble::RasterLayer* QuickLookLayer(const std::vector<ensemble::RasterLayer>& layers);

// A filled disc drawn on the map (e.g. observed and simulated rest positions).
struct MapMarker {
  Eigen::Vector2d xy_m;                // map coordinates
  std::array<unsigned char, 3> rgb{};  // colour
  int radius_px = 3;
};

// Writes the PNG atomically (GDAL's PNG driver). paths: horizontal positions, map coordinates;
// markers are drawn last, in order.
void WriteQuickLookPng(const std::string& path, const Heightfield& dem,
                       const ensemble::RasterLayer* layer,
                       const std::vector<std::vector<Eigen::Vector2d>>& paths,
                       const std::vector<MapMarker>& markers = {});

}  // namespace talus::io
