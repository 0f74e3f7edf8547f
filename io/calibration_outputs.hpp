#pragma once
// What `talus calibrate` writes (docs/calibration.md): the fitted ground table as a TOML block a
// scene can use ([ground.<name>]) and as CSV in the shape of the seed paper's Table 1,
// calibration.json (stable keys) and history.csv (every evaluation).

#include <string>

#include "calibration/calibrate.hpp"
#include "calibration/covariance.hpp"
#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"
#include "io/calibration_file.hpp"

namespace talus::io {

// The categories the calibration touched, with every field, as [ground.<name>] blocks. With the
// run, a fitted value that is unidentified or at a bound of its range carries a comment saying so.
std::string GroundTableToml(const CalibrationFile& file, const calibration::Objective& objective,
                            const GroundTable& fitted,
                            const calibration::CalibrationSummary* run = nullptr);
// The fitted shape knobs of every block with shape parameters, as [blocks.<id>] tables with a
// comment on values the observations do not support; only the header without shape parameters.
std::string ShapeTableToml(const CalibrationFile& file, const calibration::Objective& objective,
                           const calibration::CalibrationSummary& run);
// category, code[, model], then the fields of kGroundFields that apply: one row per touched
// category.
std::string GroundTableCsv(const calibration::Objective& objective, const GroundTable& fitted);
// Everything the run gave, with the version of the program that ran it.
std::string CalibrationJson(const CalibrationFile& file, const calibration::Objective& objective,
                            const calibration::CalibrationSummary& run, const std::string& version);
std::string HistoryCsv(const calibration::Objective& objective,
                       const calibration::OptimizerSummary& summary);
// The sandwich covariance at one point, as calibration.json's "uncertainty" holds it (without its
// "bootstrap" and "seeds").
std::string UncertaintyJson(const calibration::Uncertainty& uncertainty);

}  // namespace talus::io
