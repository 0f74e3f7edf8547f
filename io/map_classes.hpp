#pragma once
// The colour classes every map of a run shares: quicklook.png and report.html colour their raster
// with them, and rocks.gpkg's layer styles (layer_styles.hpp) colour its points with the same
// classes, so that a value has one colour wherever it is drawn. The classes are absolute (the same
// value has the same colour in every run), so pictures of different runs can be compared; for
// energy they include the 30 kJ and 300 kJ limits of the intensity classes used in Swiss rockfall
// hazard zoning.

#include <array>
#include <string>
#include <vector>

#include "ensemble/rasters.hpp"

namespace talus::io {

// One colour class of a legend: the values in [lower, next class's lower), in the raster's own
// unit; `label` in the unit the legend shows (e.g. kJ for an energy in J).
struct ColourClass {
  double lower = 0;
  std::string label;
  std::array<unsigned char, 3> rgb{};
};

// The legend of a layer: its title (with the unit shown) and its classes, lowest first. A value
// that is zero or below, or nodata, is not coloured. Known layers: reach_probability, energy_*,
// speed_*, jump_height_*, passages, deposits; others get five classes up to the layer's largest
// value.
struct QuickLookLegend {
  std::string title;
  std::vector<ColourClass> classes;
  // Index of the class of `value`, or -1 when the value is not coloured.
  int ClassOf(double value) const;
};
QuickLookLegend LegendOf(const ensemble::RasterLayer& layer);

// The classes of a rock's largest energy (J): those of the energy_max raster.
QuickLookLegend EnergyLegend();

// Sampled rock paths: blue, drawn with this opacity over the map.
inline constexpr std::array<unsigned char, 3> kPathRgb = {20, 60, 200};
inline constexpr double kPathOpacity = 0.6;

}  // namespace talus::io
