#pragma once
// Calibration files (CAL.toml, docs/calibration.md): an event (the EVENT.toml of talus validate,
// which names the scene and the observations), the free parameters with bounds and ties, the
// objective's weights and prior, the contact-solve tolerance of every evaluation, the optimiser and
// its budget, and the roughness measurement.
// Loading validates everything before any rock runs; errors are "<file>:<line>: <key>: <reason>".

#include <memory>
#include <string>
#include <vector>

#include "calibration/calibrate.hpp"
#include "calibration/objective.hpp"
#include "calibration/parameters.hpp"
#include "io/event_file.hpp"

namespace talus::io {

struct CalibrationFile {
  std::string path;
  EventFile event;  // its release has the file's rocks and seed applied
  std::vector<calibration::ParameterSpec> parameters;
  calibration::ObjectiveOptions objective;  // threads left at 0: the command sets them
  std::string prior_reference = "table1";   // "table1" or "scene"
  // Where objective.tolerance_m_s comes from ([solver] tolerance_m_s): "calibration file", "scene"
  // (the scene's own [solver] tolerance_m_s, tighter than the default) or "default"
  // (calibration::kCalibrationTolerance_m_s).
  std::string tolerance_source = "default";
  // The optimiser and the measurements at the optimum (its callbacks left empty: the command
  // sets them).
  calibration::CalibrationOptions options;
  std::vector<std::string> inputs;  // the calibration file and the event's inputs
  std::string inputs_hash;          // SHA-256 of the calibration file and the event's hash, hex
  // SHA-256 (hex) of what decides an optimiser's path -- the event's inputs, rocks and seed, the
  // parameters, the objective and the optimiser's options -- but not its budget (max_evaluations,
  // max_time_s), nor the roughness and uncertainty sections: a checkpoint may be resumed with
  // another budget.
  std::string path_hash;
};

// Throws InputError "<file>:<line>: <key>: <reason>".
CalibrationFile LoadCalibration(const std::string& path);

// The runs `holdout` holds out of the fit (talus calibrate --holdout): "" none, a number K (K runs
// drawn with `seed`), or a comma-separated list of run ids (returned in release order). Throws
// InputError "--holdout: <reason>".
std::vector<std::string> HoldoutRuns(const std::string& holdout,
                                     const ensemble::ReleaseSpec& release, std::uint64_t seed);

// The calibration problem of a loaded file as talus calibrate poses it: the event's scene, runs
// and observations, the file's parameters, `objective` (the file's objective options with the
// caller's threads, progress and runner), the runs `holdout` holds out (HoldoutRuns, drawn with the
// optimiser's seed), `folds` (0: no cross-validation) and the reference table of the event. Throws
// InputError for --holdout and --folds that do not fit the event, and what CalibrationProblem
// throws.
std::unique_ptr<calibration::CalibrationProblem> MakeCalibrationProblem(
    const CalibrationFile& file, const std::string& holdout, int folds,
    const calibration::ObjectiveOptions& objective);

}  // namespace talus::io
