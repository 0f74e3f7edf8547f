#pragma once
// One calibration, end to end, in one call (docs/calibration.md): what `talus calibrate` runs, and
// what a test or a binding runs without the command line. Ceres style: build a CalibrationProblem
// (it checks its inputs and throws before any rock runs), call Calibrate with CalibrationOptions,
// read the CalibrationSummary.
//
// The stages, in order: the fit (Optimize, optimize.hpp); at the optimum the objective's
// roughness and each parameter's profile (roughness.hpp), the sandwich covariance
// (covariance.hpp), the bootstrap over runs (bootstrap.hpp) and the refits with other release
// seeds (seeds.hpp); the fitted runs scored before and after the fit (the observed-vs-simulated
// plots); the held-out runs scored; and a k-fold cross-validation by run, each fold an
// optimisation of its own (holdout.hpp).
//
// Files, printing, processes and checkpoints stay with the caller, who hears of the run through
// the options' callbacks: a few lines of text for people at each stage, every evaluation of every
// optimisation (the fit is "fit", the folds "fold1", "fold2", ...) and the end of each
// optimisation. Evaluations of an interrupted run, replayed per optimisation, resume it to the
// result an uninterrupted one gives. What a callback throws stops the run and comes out of
// Calibrate.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calibration/bootstrap.hpp"
#include "calibration/covariance.hpp"
#include "calibration/holdout.hpp"
#include "calibration/objective.hpp"
#include "calibration/optimize.hpp"
#include "calibration/optimizer.hpp"
#include "calibration/roughness.hpp"
#include "calibration/seeds.hpp"

namespace talus::calibration {

// Checks of the fit on runs it did not see.
struct HeldOutChecks {
  std::vector<std::string> holdout;  // ids of runs left out of the fit, scored after it
  int folds = 0;                     // k-fold cross-validation by run of the fitted runs; 0: none
  std::uint64_t seed = 1;            // how the fitted runs are dealt into the folds
  // The table the held-out and cross-validated runs are also scored with (e.g. Table 1).
  std::optional<GroundTable> reference;
};

// What is fitted to what: the scene and its runs, the observations, the free parameters, the
// objective's options (its threads and ensemble runner serve every stage), the runs held out.
class CalibrationProblem {
 public:
  // Copies what it needs. Throws talus::InputError for a held-out id that is not a run, folds
  // that do not fit the runs left, and what Objective's constructor throws.
  CalibrationProblem(const Scene& scene, const ensemble::ReleaseSpec& release,
                     const fieldobs::ObservationSet& observations,
                     std::vector<ParameterSpec> parameters, const ObjectiveOptions& options,
                     HeldOutChecks checks = {});

  // The fit's objective: the runs not held out, with their observations and those of the whole
  // scene.
  const Objective& objective() const { return objective_; }
  const RunSubset& fitted_runs() const { return fit_; }
  const std::vector<std::string>& holdout() const { return checks_.holdout; }
  const std::vector<std::vector<std::string>>& folds() const { return folds_; }
  const std::optional<GroundTable>& reference() const { return checks_.reference; }
  // The held-out runs with their observations (none of the whole scene).
  RunSubset HeldOutRuns() const;
  // The fitted runs without fold f (0-based) with the scene-wide observations, and fold f alone.
  RunSubset FoldTraining(int f) const;
  RunSubset FoldRuns(int f) const;
  // An objective like the fit's on other runs (a fold's training runs).
  Objective ObjectiveOn(const RunSubset& runs) const;

 private:
  Scene scene_;
  ensemble::ReleaseSpec release_;
  fieldobs::ObservationSet observations_;
  std::vector<ParameterSpec> parameters_;
  ObjectiveOptions options_;
  HeldOutChecks checks_;
  RunSubset fit_;
  std::vector<std::vector<std::string>> folds_;
  Objective objective_;
};

struct CalibrationOptions {
  // The fit's optimiser, and each fold's (replay and on_evaluation come from below).
  OptimizerOptions optimizer;
  bool roughness = true;  // measure the roughness and profile every parameter at the optimum
  RoughnessOptions roughness_options;
  ProfileOptions profile_options;
  // The covariance at the optimum. fd_step 0 in uncertainty_options: the optimiser's step
  // (Ceres), else the roughness measurement's recommendation, else 0.01.
  bool uncertainty = true;
  UncertaintyOptions uncertainty_options;
  // The bootstrap over runs beside the covariance (resamples 0: off). Its resolution when none
  // is given: the covariance's finite-difference step.
  BootstrapOptions bootstrap_options;
  std::optional<double> bootstrap_resolution;
  // Refits with other release seeds after the bootstrap, combined with it (seeds 0: off).
  SeedRefitOptions seed_options;

  // Evaluations of an earlier, interrupted run of the same calibration, per optimisation
  // ("fit", "fold1", ...): served in order instead of running rocks (OptimizerOptions::replay).
  std::map<std::string, std::vector<Evaluation>> replay;
  // Called after every evaluation of an optimisation (index: its place in that optimisation).
  std::function<void(const std::string& stage, const Evaluation& evaluation, int index)>
      on_evaluation;
  // Called when an optimisation begins, and when it has returned (before its report).
  std::function<void(const std::string&stage)> on_optimization_begins, on_optimization_ends;
  // Text for people as the stages go: what starts, and each stage's report.
  std::function<void(const std::string& text)> on_progress;
};

// One fold of a cross-validation: the fit without it, and its runs' scores.
struct FoldRun {
  OptimizerSummary summary;
  HeldOutScores scores;
};

struct CalibrationSummary {
  OptimizerSummary fit;  // the fit; fit.best is the fitted point
  GroundTable fitted;    // the scene's table with the fitted values
  // The release's blocks with the fitted shape parameters; empty without shape parameters.
  std::vector<ensemble::Block> fitted_blocks;
  std::optional<RoughnessReport> roughness;
  std::vector<ParameterProfile> profiles;
  std::optional<Uncertainty> uncertainty;
  std::optional<Bootstrap> bootstrap;  // with the uncertainty, when asked for
  std::optional<SeedRefits> seeds;     // after the bootstrap, when asked for
  // The fitted runs scored with the initial and with the fitted table.
  HeldOutScores before, after;
  std::optional<HeldOutScores> holdout;
  std::vector<FoldRun> folds;
  std::vector<HeldOutKind> cross_validated;  // per kind, over every fold's runs
  int threads = 0;                           // the objective's worker threads (0: all cores)
  double wall_time_s = 0;

  // Whether a budget (evaluations or time) ended the fit or a fold's fit.
  bool BudgetEndedAFit() const;
  std::string BriefReport() const;  // one line
  std::string FullReport() const;   // every stage's report
};

// A fitted value further than this many sds from its own prior's mean is a warning: under the
// prior, 2 sds is the 95 % interval's edge, and the data have pulled the value beyond it.
constexpr double kPriorConflictSds = 2.0;

// What in a calibration's result deserves a warning, one sentence each, in this order: a
// parameter the profiles or the covariance find unidentified; a fitted value more than
// kPriorConflictSds from its own prior's mean; a fitted value at a bound of its
// range (within 1e-3 of the range: the optimum may lie beyond); a profile point below the reported
// optimum by more than the objective's noise level (the optimum is then not the best point
// evaluated; within the noise it is not reported); a kind that the held-out runs, or the folds'
// runs, score worse with the fitted values than with the reference table. `objective` is the fit's.
std::vector<std::string> CalibrationWarnings(const CalibrationSummary& run,
                                             const Objective& objective);

// Runs the calibration. Throws what the objective and the callbacks throw,
// std::invalid_argument for invalid options, and std::runtime_error when the fit (or a fold's)
// has no usable solution.
CalibrationSummary Calibrate(const CalibrationProblem& problem, const CalibrationOptions& options);

}  // namespace talus::calibration
