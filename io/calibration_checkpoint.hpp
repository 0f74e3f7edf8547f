#pragma once
// The checkpoint of `talus calibrate` (DIR/checkpoint.json, docs/calibration.md): every
// evaluation of each optimisation of the run so far (the fit, and the fit of each fold), with
// every number as JSON writes it (shortest round-trip form), so that a resumed calibration
// replays them bit for bit (OptimizerOptions::replay). It names the calibration's inputs hash
// (CalibrationFile::path_hash, as "path_sha256") and the held-out runs and folds, and is refused
// for another calibration; a SHA-256 checksum over all it holds ("sha256") refuses a file edited
// or damaged, and a checkpoint of an older talus (FNV-1a checksum) is refused by name.

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

// What every evaluation of a calibration holds: the sizes of its vectors.
struct EvaluationShape {
  int dimension = 0;  // coordinates: entries of u and values
  int kinds = 0;      // observation kinds: entries of kind_scores and kind_scored
  int residuals = 0;  // entries of residuals
};

std::string CheckpointJson(const CalibrationCheckpoint& checkpoint);
// Throws InputError naming the file when it cannot be read or parsed, has no checksum or an older
// talus's, or its checksum does not match what it holds; the message says to remove it and start
// afresh.
CalibrationCheckpoint ReadCheckpoint(const std::string& path);
// Throws InputError naming the file `path` and the evaluation ("stages.fit[3]") when the
// checkpoint has a stage that `shapes` (by stage: "fit", "fold1", ...) lacks, or an evaluation
// does not have its stage's shape or holds a non-finite number where an evaluation never does.
void CheckEvaluations(const CalibrationCheckpoint& checkpoint, const std::string& path,
                      const std::map<std::string, EvaluationShape>& shapes);

}  // namespace talus::io
