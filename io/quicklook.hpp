#pragma once
// quicklook.png: a picture of a run for people who would rather look than read. The DEM's
// hillshade (north up), one raster on top in fixed classes (reach probability, else the largest
// energy, speed or passages; transparent where no rock passed), the paths of sampled rocks in
// blue, and beside the map a legend with the classes and their units, a scale bar and a north
// arrow. The classes are those of every map of a run (map_classes.hpp).

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "ensemble/rasters.hpp"
#include "io/map_classes.hpp"
#include "solver/terrain.hpp"

namespace talus::io {

// The layer the quick-look shows: the first of reach_probability, energy_max, speed_max, passages
// in `layers`, or nullptr.
const ensemble::RasterLayer* QuickLookLayer(const std::vector<ensemble::RasterLayer>& layers);

// A filled disc drawn on the map (e.g. observed and simulated rest positions); markers with a
// label are listed in the legend (once per label).
struct MapMarker {
  Eigen::Vector2d xy_m;                // map coordinates
  std::array<unsigned char, 3> rgb{};  // colour
  int radius_px = 3;
  std::string label;
};

// A named polyline drawn on the map (evaluation lines): black over a white halo, its name at its
// first vertex; listed in the legend.
struct MapLine {
  std::string name;
  std::vector<Eigen::Vector2d> xy_m;  // map coordinates
};

// The picture's layout in pixels: the map is `scale` pixels per DEM cell, north up, at the top
// left; the legend panel is to its right.
struct QuickLookLayout {
  int scale = 1;
  int map_width = 0, map_height = 0;
  int width = 0, height = 0;
};
QuickLookLayout QuickLookLayoutOf(const GridGeometry& grid);

// The rocks' paths as the maps of a run show them: translucent blue lines on a transparent layer
// of the map's size (QuickLookLayoutOf(grid)), drawn once and laid over each map, since every map
// of a run shows the same paths. Stroking them was most of a map's cost: 4.6·10⁸ instructions for
// the 4 maps of a 50-rock tirol run (40 paths), of 8.6·10⁹ for the whole run (bench/README.md,
// "What a run pays besides its rocks").
// A vertex within a pixel of the last one drawn is skipped (never a path's last): the line it
// would add is shorter than the line is wide, and a slow rock's samples crowd into one pixel.
// The line drawn stays within a pixel of the path.
struct MapPathsLayer;  // the layer drawn (io/quicklook.cpp)
class MapPaths {
 public:
  MapPaths() = default;  // no paths
  // paths: horizontal positions, map coordinates of `grid`.
  MapPaths(const GridGeometry& grid, const std::vector<std::vector<Eigen::Vector2d>>& paths);
  std::size_t size() const { return count_; }  // the paths given (the legend counts them)
  // The layer, for the maps of the grid the paths were drawn for (QuickLookPngOf); null without a
  // path of two points or more.
  const std::shared_ptr<const MapPathsLayer>& layer() const { return layer_; }

 private:
  std::shared_ptr<const MapPathsLayer> layer_;
  std::size_t count_ = 0;
};

// The picture as PNG bytes (cairo), and written atomically to `path`. paths: horizontal
// positions, map coordinates; lines are drawn over the paths, markers last, in order. The same
// inputs give the same bytes. QuickLookPngOf takes paths already drawn for dem's grid, for a run
// that draws several maps.
std::string QuickLookPngOf(const Heightfield& dem, const ensemble::RasterLayer* layer,
                           const MapPaths& paths, const std::vector<MapMarker>& markers = {},
                           const std::vector<MapLine>& lines = {});
std::string QuickLookPng(const Heightfield& dem, const ensemble::RasterLayer* layer,
                         const std::vector<std::vector<Eigen::Vector2d>>& paths,
                         const std::vector<MapMarker>& markers = {},
                         const std::vector<MapLine>& lines = {});
void WriteQuickLookPng(const std::string& path, const Heightfield& dem,
                       const ensemble::RasterLayer* layer,
                       const std::vector<std::vector<Eigen::Vector2d>>& paths,
                       const std::vector<MapMarker>& markers = {},
                       const std::vector<MapLine>& lines = {});

// A "nice" length for a scale bar at most `at_most_m` long: 1, 2 or 5 × 10^k m.
double ScaleBarLength(double at_most_m);

}  // namespace talus::io
