#pragma once
// rocks.gpkg (docs/scenes.md): the rocks of a run as GIS layers QGIS opens directly, in the DEM's
// CRS: `end_points` (one 3-D point per rock at its end, with every column of rocks.csv as a field)
// and, when trajectories.h5 was written, `paths` (one 3-D line per rock through its trajectory
// samples, with the rock, its run and how it ended), and with evaluation lines
// `evaluation_crossings` (one 3-D point per row of evaluation_lines.csv, at the first crossing of
// the centre of mass, with every column as a field), and the scene's releases, evaluation lines,
// barriers and trees (GeoPackageScene); every layer has a default QGIS style in the table
// `layer_styles` (layer_styles.hpp: the quick-look's classes). Built from rocks.csv and
// trajectories.h5 after they are complete, so a run split into parts gives the same file; the
// GeoPackage's timestamps are fixed (2000-01-01T00:00:00Z, the styles' update_time too), so the
// same rocks give the same bytes.

#include <string>
#include <vector>

#include "ensemble/evaluation_lines.hpp"
#include "ensemble/release.hpp"
#include "solver/barriers.hpp"
#include "solver/forest.hpp"

namespace talus::io {

// What the scene puts on the map beside the rocks: its releases (layers `release_points`,
// `release_lines`, `release_polygons` with the release's index and name; a run table's runs as
// points), its evaluation lines (`evaluation_lines`, with their names) and barriers (`barriers`,
// with name, type, height_m and capacity_kj). Layers without features are not written.
// With a forest of explicit trees: layer `trees`, a 3-D point per stem at its foot with its index
// (`tree`, as in tree_impacts.csv), `dbh_cm`, `breaking_energy_kj` and what the run's rocks did to
// it, from the complete `tree_impacts_csv`: `rocks_hit` (rocks that touched it), `impacts` (their
// contact episodes), `broken` (rocks that broke it) and `absorbed_kj` (energy it took, summed).
// Every stem is a feature, hit or not.
struct GeoPackageScene {
  const ensemble::ReleaseSpec* release = nullptr;
  const std::vector<ensemble::EvaluationLine>* evaluation_lines = nullptr;
  const std::vector<Barrier>* barriers = nullptr;
  const Forest* forest = nullptr;
  std::string tree_impacts_csv = {};
};

// Writes the GeoPackage atomically. `trajectories_h5` empty: no `paths` layer;
// `evaluation_lines_csv` empty: no `evaluation_crossings` layer; `barriers_csv` empty: no
// `barrier_impacts` layer (a point per row of barriers.csv). `crs_wkt` empty: local
// coordinates in metres (the analytic plane), an engineering CRS. Throws std::runtime_error naming
// the file and the reason, and InputError for a CSV file it cannot read.
void WriteRocksGeoPackage(const std::string& path, const std::string& rocks_csv,
                          const std::string& trajectories_h5, const std::string& crs_wkt,
                          const std::string& evaluation_lines_csv = "",
                          const std::string& barriers_csv = "", const GeoPackageScene& scene = {});

}  // namespace talus::io
