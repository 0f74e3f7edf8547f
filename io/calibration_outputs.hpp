#pragma once
// What `talus calibrate` writes (docs/calibration.md): the fitted ground table as a TOML block a
// scene can use ([ground.<name>]) and as CSV in the shape of the seed paper's Table 1,
// calibration.json (stable keys) and history.csv (every evaluation).

#include <optional>
#include <string>
#include <vector>

#include "calibration/bootstrap.hpp"
#include "calibration/seeds.hpp"
#include "calibration/holdout.hpp"
#include "calibration/least_squares.hpp"
#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"
#include "calibration/roughness.hpp"
#include "io/calibration_file.hpp"

namespace talus::io {

// One fold of a cross-validation: the fit without it, and its runs' scores.
struct FoldRun {
  calibration::Summary summary;
  calibration::HeldOutScores scores;
};

// Everything a calibration run gave, for calibration.json.
struct CalibrationRun {
  std::string version;
  int threads = 1;
  double wall_time_s = 0;
  calibration::Summary summary;
  std::optional<calibration::RoughnessReport> roughness;
  std::vector<calibration::ParameterProfile> profiles;
  std::optional<calibration::Uncertainty> uncertainty;
  std::optional<calibration::Bootstrap> bootstrap;  // with the uncertainty, when asked for
  std::optional<calibration::SeedRefits> seeds;     // after the bootstrap, when asked for
  std::optional<calibration::HeldOutScores> holdout;
  std::vector<FoldRun> folds;
  std::vector<std::string> not_scored;  // observed values the event holds but cannot score
};

// Held-out scores per kind, fitted against reference, as a few lines for people.
std::string HeldOutReport(const calibration::HeldOutScores& scores);

// The categories the calibration touched, with every field, as [ground.<name>] blocks.
std::string GroundTableToml(const CalibrationFile& file, const calibration::Objective& objective,
                            const GroundTable& fitted);
// category, code[, model], then the fields of kGroundFields that apply: one row per touched category.
std::string GroundTableCsv(const calibration::Objective& objective, const GroundTable& fitted);
std::string CalibrationJson(const CalibrationFile& file, const calibration::Objective& objective,
                            const CalibrationRun& run);
std::string HistoryCsv(const calibration::Objective& objective,
                       const calibration::Summary& summary);

}  // namespace talus::io
