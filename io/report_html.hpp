#pragma once
// report.html: a one-page report of a `talus simulate` run for a browser, in one self-contained
// file (maps as embedded PNG, histograms as inline SVG, no scripts, nothing fetched): what ran
// (scene, inputs, rock, releases, ground table, solver options), how the rocks ended, the maps
// with their legends, the distributions of runout, energy and jump height over the rocks, and the
// summary of the evaluation lines (summary.json's "evaluation_lines").
// It holds no timings or thread counts, so a run split into parts, or over MPI ranks, gives the
// same bytes as one run.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "ensemble/rasters.hpp"
#include "io/quicklook.hpp"
#include "solver/terrain.hpp"

namespace talus::io {

// Per-rock values the report's histograms show, read back from rocks.csv.
struct RockColumns {
  std::vector<double> runout_m, max_kinetic_energy_j, max_jump_height_m, max_speed_m_s,
      travel_angle_deg;
};

// Reads the columns above from a rocks.csv (io/rocks_csv.hpp), streaming: memory is five numbers
// per rock. Throws naming the file and line when it cannot be read or a value is not a number.
RockColumns ReadRockColumns(const std::string& rocks_csv);

// A histogram of `values` in `bins` equal bins from 0 (or the smallest value, when negative) to the
// largest, as SVG, with n, median, 95th percentile and largest value in the corner.
std::string HistogramSvg(const std::string& title, const std::string& x_label,
                         const std::vector<double>& values, int bins = 20);

struct RunReportInput {
  std::string summary_json;  // summary.json's text (its timings and threads are not shown)
  const Heightfield* dem = nullptr;
  const std::vector<ensemble::RasterLayer>* layers = nullptr;
  std::vector<std::vector<Eigen::Vector2d>> paths;  // the quick-look's sampled paths
  std::vector<MapLine> lines;                       // evaluation lines, drawn on the maps
  RockColumns rocks;
};

// The page's HTML.
std::string RunReportHtml(const RunReportInput& input);

}  // namespace talus::io
