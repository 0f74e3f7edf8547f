#pragma once
// QGIS layer styles (QML) for the layers of rocks.gpkg, so that QGIS draws a run as the quick-look
// does when the GeoPackage is opened: points graduated by energy in the classes of every map of a
// run (map_classes.hpp), paths in the quick-look's blue, evaluation lines and barriers black over a
// white halo. rocks.gpkg keeps them in its `layer_styles` table, one default style per layer.

#include <array>
#include <string>

#include "io/map_classes.hpp"

namespace talus::io {

enum class SymbolKind { kMarker, kLine, kFill };

// One symbol for every feature: `rgb` at `opacity` (0..1); a line `width_mm` wide (a marker's
// diameter, a fill's outline); `halo`: a line drawn over a white line twice as wide.
struct SingleSymbol {
  SymbolKind kind = SymbolKind::kMarker;
  std::array<unsigned char, 3> rgb{};
  double opacity = 1;
  double width_mm = 0.5;
  bool halo = false;
};
std::string SingleSymbolQml(const SingleSymbol& symbol);

// Markers coloured by the numeric field `field` (in the classes' unit) in the classes of `legend`:
// one range per class, from its lower bound to the next class's (the last one open above), with
// the legend's labels.
std::string GraduatedMarkerQml(const std::string& field, const QuickLookLegend& legend);

}  // namespace talus::io
