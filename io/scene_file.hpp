#pragma once
// Scene files (TOML, docs/scenes.md): loading and validation. Every error names the file, the
// line and key, and the reason, and is raised before any simulation starts.

#include <optional>
#include <string>
#include <vector>

#include "ensemble/evaluation_lines.hpp"
#include "ensemble/rasters.hpp"
#include "ensemble/release.hpp"
#include "io/raster.hpp"
#include "pointclouds/rock_source.hpp"
#include "solver/scene.hpp"

namespace talus::io {

// The [output] table.
struct OutputSpec {
  bool trajectories = false;
  double trajectory_interval_s = 0.01;
  // The rasters asked for, in the order given, each once (names: ensemble::kRasterKindNames).
  std::vector<ensemble::RasterKind> rasters;
  bool quicklook =
      true;  // quicklook.png: hillshade, reach probability or energy, sample trajectories
  bool geopackage = true;  // rocks.gpkg: end points and (with trajectories) paths as GIS layers
  bool report = true;       // report.html: one page with what ran, endings, maps and histograms
  // The percentiles (percent, ascending, each 1 .. 99) of the <quantity>_p<NN> rasters.
  std::vector<int> percentiles = {95};
  io::RasterFormat raster_format = io::RasterFormat::kGeoTiff;  // kRasterFormatNames

  // The raster request on `grid` (nothing when no raster is listed).
  ensemble::RasterRequest Request(const GridGeometry& grid) const;
};

// How the shape of each rock of a block varies about the block's ([blocks] size_variation,
// roughness_variation; with shape_per_rock): every axis by a factor exp(a (2U - 1)), the three
// then divided by their geometric mean (the ratios vary, the product of the axes does not); the
// roughness by b (2U - 1), kept in 0 .. 0.5. U uniform on [0, 1) from the rock's shape seed.
struct ShapeVariation {
  double size = 0;       // a, 0 .. 0.5
  double roughness = 0;  // b, 0 .. 0.25
};

// The knobs of one rock of a block whose shapes vary per rock, drawn from the rock's shape seed.
ensemble::ShapeKnobs VariedKnobs(const ensemble::ShapeKnobs& knobs, const ShapeVariation& v,
                                 std::uint64_t seed);

// A run of a run table whose start lies where the DEM's height departs from the surveyed ground
// height (column ground_z_m) by more than [release] ground_z_tolerance_m.
struct GroundMismatch {
  std::string run;
  std::string where;  // "file:line: column 'ground_z_m'"
  double dem_z_m = 0, surveyed_z_m = 0;
};

// A loaded, validated scene file.
struct SceneFile {
  std::string path;               // as given
  Scene scene;                    // IsValid() holds
  ensemble::ReleaseSpec release;  // IsValid() holds, every release vertex on valid DEM cells
  OutputSpec output;
  // [evaluation_lines]: >= 2 finite vertices each, non-zero length, at least partly on the DEM,
  // unique non-empty names; empty when the scene has none.
  std::vector<ensemble::EvaluationLine> evaluation_lines;
  pointclouds::RockSpec rock;  // the [rock] table
  bool has_rock = false;       // the scene has a [rock] table (else only [blocks])
  std::vector<pointclouds::RockSpec> block_specs;  // [blocks], parallel to release.blocks
  std::vector<GroundMismatch> ground_mismatches;    // runs starting off the surveyed ground
  bool shape_per_rock = false;                     // every rock has a seeded shape of its own
  ShapeVariation shape_variation;                  // of blocks' shapes per rock ([blocks])
  std::string rock_description;     // e.g. "eota221 0.93 x 0.93 x 0.47 m, bevel 0.12 m"
  std::string crs_wkt;              // the DEM's CRS; empty for the plane or a DEM without CRS
  std::optional<PlaneSpec> plane;   // [terrain] plane, when the terrain is the analytic plane
  std::string terrain_description;  // e.g. "dem.tif (270 x 370 cells of 5 m)"
  std::vector<std::string> inputs;  // the scene file and every data file it read
  std::string inputs_hash;          // SHA-256 over the contents of `inputs`, hex
  SolverPreset solver_preset = SolverPreset::kDefault;  // [solver] preset, or --preset
  // [solver] self_check: rocks rerun at half the step to measure the run's own step error
  // (ensemble/self_check.hpp); 0: none. talus simulate --self-check N wins over it.
  long self_check = 0;
  std::vector<std::string> solver_keys_given;           // the preset's knobs the scene sets itself
  // --preset given on the command line (UseSolverPreset): it wins over the scene's own keys;
  // solver_keys_overridden lists those whose values it changed, as "dt_s = 0.002 -> 0.001".
  bool solver_preset_from_command_line = false;
  std::vector<std::string> solver_keys_overridden;
  // Inputs that load but look wrong (e.g. a few points dominating the rock's hull), each naming
  // the file, line and key: printed by talus simulate and listed in summary.json.
  std::vector<std::string> warnings;
  // [forest]: where its trees came from (scene.forest holds them); empty without the table.
  struct ForestStand {
    double area_m2 = 0, stems_per_ha = 0, dbh_cm = 0, dbh_sd_cm = 0;
    long trees = 0;       // drawn
    std::string species;  // of [forest.species]; "" without
  };
  bool has_forest = false;
  std::string trees_file;  // [forest] trees, resolved; "" without
  long trees_from_file = 0;
  std::string stands_file;          // [forest] stands_file, resolved; "" without
  std::vector<ForestStand> stands;  // inline stands first, then those of stands_file
  std::uint64_t forest_seed = 0;
  // [forest] model: "trees" (explicit stems in scene.forest; has_forest), "drag" (the drag layer
  // in scene.forest_drag, with the stands above and the rasters below), "" without [forest].
  std::string forest_model;
  std::string forest_density_raster, forest_dbh_raster;  // model = "drag", resolved; "" without
  std::string forest_raster_species;  // model = "drag": the rasters' stands' species; "" without
  long forest_drag_cells = 0;                            // model = "drag": DEM nodes in a stand
  ForestModel forest_drag_model;  // model = "drag": its breaking energy and height
};

// Loads and validates a scene. Throws talus::InputError with "<file>:<line>: <key>: <reason>".
SceneFile LoadScene(const std::string& path);
// The same for a scene given as TOML text (e.g. built from values in Python): `path` names it in
// errors and relative paths in it are resolved from its folder; it need not exist. inputs lists
// the files the scene read; inputs_hash covers the text and those files.
SceneFile LoadSceneText(const std::string& text, const std::string& path);

// Sets the solver's accuracy knobs to `preset` as talus simulate --preset asks: the preset wins
// over the values the scene's [solver] gives itself (a check with "accurate" must run accurately),
// and the keys it changed are listed in scene.solver_keys_overridden.
void UseSolverPreset(SceneFile& scene, SolverPreset preset);

}  // namespace talus::io
