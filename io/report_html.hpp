#pragma once
// report.html: a one-page report of a `talus simulate` run for a browser, in one self-contained
// file (maps as embedded PNG, histograms as inline SVG, no scripts, nothing fetched): what ran
// (scene, inputs, rock, releases, ground table, solver options), how the rocks ended, the maps
// with their legends, the distributions of runout, energy and jump height over the rocks, and the
// summary of the evaluation lines (summary.json's "evaluation_lines"). Its statistics over the
// rocks are read from rocks.csv in bounded memory (common/column_statistics.hpp).
// It holds no timings or thread counts, so a run split into parts, or over MPI ranks, gives the
// same bytes as one run.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/column_statistics.hpp"
#include "ensemble/rasters.hpp"
#include "io/quicklook.hpp"
#include "solver/terrain.hpp"

namespace talus::io {

// The per-rock columns of rocks.csv the report shows, as numbered in a RockColumns source.
enum RockColumn : std::size_t {
  kRunoutColumn,       // runout_m
  kEnergyColumn,       // max_kinetic_energy_j, in the report's unit (io/html_page.hpp kEnergyUnit)
  kJumpHeightColumn,   // max_jump_height_m
  kSpeedColumn,        // max_speed_m_s
  kTravelAngleColumn,  // travel_angle_deg
  kRockColumnCount
};

// The columns above of a rocks.csv (io/rocks_csv.hpp) as a source for SummarizeColumns
// (common/column_statistics.hpp), which reads the file again on each call: memory does not grow
// with the rocks. An empty field is NaN. Opens the file and finds the columns at once; throws
// InputError naming the file, and the line when a value is not a number.
ColumnSource RockColumns(const std::string& rocks_csv);

// A histogram of `values` in `bins` equal bins from 0 (or the smallest value, when negative) to the
// largest, as SVG, with n, median, 95th percentile and largest value in the corner.
std::string HistogramSvg(const std::string& title, const std::string& x_label,
                         const std::vector<double>& values, int bins = 20);

struct RunReportInput {
  std::string summary_json;  // summary.json's text (its timings and threads are not shown)
  const Heightfield* dem = nullptr;
  const std::vector<ensemble::RasterLayer>* layers = nullptr;
  MapPaths paths;              // the quick-look's sampled paths, drawn for dem's grid
  std::vector<MapLine> lines;  // evaluation lines, drawn on the maps
  // quicklook.png's bytes, when the run wrote it from these paths and lines: the map of
  // QuickLookLayer(*layers), shown again instead of drawn again.
  std::string quicklook_png;
  ColumnSource rocks;  // per-rock values (RockColumns); none when empty
  std::size_t statistics_budget_bytes = kColumnStatisticsBudgetBytes;  // for SummarizeColumns
};

// The page's HTML.
std::string RunReportHtml(const RunReportInput& input);

}  // namespace talus::io
