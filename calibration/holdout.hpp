#pragma once
// Held-out checking: leave runs out of a fit and score them with the fitted and the reference
// parameters (talus calibrate --holdout), and k-fold cross-validation by run (--folds).
//
// A subset of runs is a release with only those runs (in their original order; blocks kept) and
// the observations of those runs. Its rocks are numbered within the subset, so they are other
// rocks (other orientations) than the same runs get in the full release -- still deterministic.
// Observations of the whole scene (no run) stay in the fit and are never held out.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "calibration/objective.hpp"
#include "ensemble/release.hpp"
#include "fieldobs/observations.hpp"
#include "fieldobs/validation.hpp"
#include "solver/scene.hpp"

namespace talus::calibration {

struct RunSubset {
  ensemble::ReleaseSpec release;
  fieldobs::ObservationSet observations;
};

// The runs `runs` (ids of release.runs) with their observations; with keep_scene_wide, also the
// observations of the whole scene. Throws talus::InputError for an id that is not a run.
RunSubset SelectRuns(const ensemble::ReleaseSpec& release,
                     const fieldobs::ObservationSet& observations,
                     const std::vector<std::string>& runs, bool keep_scene_wide);
// The ids of the runs not in `runs`, in release order.
std::vector<std::string> OtherRuns(const ensemble::ReleaseSpec& release,
                                   const std::vector<std::string>& runs);

// k runs drawn without replacement by a seeded shuffle (the same on every platform), in release
// order. 1 <= k < number of runs.
std::vector<std::string> PickRuns(const ensemble::ReleaseSpec& release, int k, std::uint64_t seed);
// The runs dealt into k folds of (almost) equal size after a seeded shuffle, each in release
// order. 2 <= k <= number of runs.
std::vector<std::vector<std::string>> Folds(const ensemble::ReleaseSpec& release, int k,
                                            std::uint64_t seed);

// Scores of held-out runs, per observation kind: mean CRPS (energy score for deposits) with the
// fitted and with the reference parameters, over the same observations.
struct HeldOutKind {
  std::string kind, unit;
  int observations = 0, scored = 0;
  double fitted = std::numeric_limits<double>::quiet_NaN();
  double reference = std::numeric_limits<double>::quiet_NaN();  // NaN without a reference
};
struct HeldOutScores {
  std::vector<std::string> runs;
  std::vector<HeldOutKind> kinds;
  // Per observation (as fieldobs::Validate gives them; reference_score NaN without a reference).
  std::vector<fieldobs::ObservationScore> observations;
  long rocks = 0;
  double wall_time_s = 0;
  std::string Report() const;  // per kind, fitted against reference, a few lines for people
};

// Runs `subset` on `scene` with the ground table `fitted` (and the blocks `fitted_blocks` in place
// of the subset's, when given: fitted shapes), and with `reference` and the subset's own blocks
// when given, and scores its observations. threads 0: all cores; episodes: record contact
// episodes (impact and scar observations need them); runner: how the rocks run (objective.hpp;
// empty: here).
HeldOutScores ScoreRuns(const Scene& scene, const RunSubset& subset, const GroundTable& fitted,
                        const GroundTable* reference, int threads, bool episodes,
                        const EnsembleRunner& runner = {},
                        const std::vector<ensemble::Block>* fitted_blocks = nullptr);

// Per kind, the means over every observation of several held-out sets (the folds of a
// cross-validation), fitted and reference.
std::vector<HeldOutKind> PoolKinds(const std::vector<HeldOutScores>& sets);

}  // namespace talus::calibration
