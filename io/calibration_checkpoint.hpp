#pragma once
// The checkpoint of `talus calibrate` (DIR/checkpoint.json, docs/calibration.md): every
// evaluation of each optimisation of the run so far (the fit, and the fit of each fold), with
// every number as JSON writes it (shortest round-trip form), so that a resumed calibration
// replays them bit for bit (OptimizerOptions::replay). It names the calibration's inputs hash
// (CalibrationFile::path_hash) and the held-out runs and folds, and is refused for another
// calibration.

#include <map>
#include <string>
#include <vector>

#include "calibration/objective.hpp"

namespace talus::io {

struct CalibrationCheckpoint {
  std::string path_hash;
  std::vector<std::string> holdout;  // held-out run ids
  int folds = 0;
  // Per optimisation ("fit", "fold1", ...): its evaluations in order.
  std::map<std::string, std::vector<calibration::Evaluation>> stages;
};

std::string CheckpointJson(const CalibrationCheckpoint& checkpoint);
// Throws InputError naming the file when it cannot be read or parsed.
CalibrationCheckpoint ReadCheckpoint(const std::string& path);

}  // namespace talus::io
