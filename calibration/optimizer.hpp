#pragma once
// The vocabulary every optimiser of the calibration shares, at the bottom of the module: the
// algorithms by name, the options, how a run ended (Termination), each start's record and the
// OptimizerSummary with its brief and full report (Ceres style), and the start points. The
// optimisers work on the objective (objective.hpp) in the unit cube: NLopt's derivative-free
// methods (nlopt_optimizer.hpp) and Ceres Solver's bounded nonlinear least squares on the residual
// vector (least_squares.hpp), two back-ends beside each other that keep their record through the
// Evaluator (evaluator.hpp); Optimize (optimize.hpp) chooses one by name. Every evaluation is
// kept, and a checkpoint's evaluations can be replayed so that an interrupted calibration resumes
// to the identical result.
//
// Infeasible vectors (mu_min > mu_max where both are free; NLopt keeps to the box itself) run no
// rock and get the finite penalty ObjectiveOptions::infeasible_value * (1 + violation), far above
// any feasible value of a normalised objective (a normalised term is about 1 - skill), which every
// one of these algorithms handles as a bad point.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calibration/objective.hpp"

namespace talus::calibration {

// The algorithms by name: "bobyqa", "sbplx" (local), "crs2_lm", "direct_l", "isres" (global),
// "ceres" (local, least squares with numeric derivatives).
const std::vector<std::string>& AlgorithmNames();
bool IsLocalAlgorithm(const std::string& name);

struct OptimizerOptions {
  std::string algorithm = "bobyqa";
  int max_evaluations = 200;  // objective evaluations in all (all starts), >= 1
  double max_time_s = 0;      // wall time in all; 0: no limit
  double ftol_rel = 1e-4;     // stop when f changes by less than this relative amount
  double ftol_abs = 0;        // ... or this absolute amount (choose above the roughness)
  double xtol_abs = 1e-3;     // ... or the step in every unit coordinate is below this
  double initial_step = 0.1;  // local methods' first step, unit coordinates (fraction of range)
  int population = 0;         // CRS2-LM and ISRES population; 0: NLopt's default
  int starts = 1;             // the start point, then starts - 1 design points
  std::string start_design = "sobol";    // or "lhs"
  std::uint64_t seed = 1;                // designs and the stochastic methods (CRS2-LM, ISRES)
  std::optional<Eigen::VectorXd> start;  // unit coordinates; default: the scene's table, clamped
  // Ceres: the central-difference step in unit coordinates (fraction of each range); 0: chosen at
  // the start point from the Jacobian's measured noise and curvature (ChooseFiniteDifferenceStep).
  double fd_step = 0;
  // Evaluations of an earlier, interrupted run of the same calibration (a checkpoint), served in
  // order instead of running rocks: the optimiser retraces its path bit for bit and goes on from
  // where the checkpoint ends. An optimiser asking for another point than the next one recorded
  // is an error (the checkpoint belongs to another calibration).
  std::vector<Evaluation> replay;
  // Called after every evaluation (on the calling thread); may throw to stop (e.g. interrupted):
  // the optimiser stops and the exception comes out of Optimize (optimize.hpp).
  std::function<void(const Evaluation&, int evaluation)> on_evaluation;

  bool IsValid(std::string* why) const;
};

enum class Termination {
  kConvergence,     // a tolerance was met
  kMaxEvaluations,  // the evaluation budget is spent
  kMaxTime,         // the wall-time budget is spent
  kFailure,         // NLopt failed (round-off limited, invalid arguments, out of memory)
};
const char* ToString(Termination termination);  // "convergence", ...

struct StartRecord {
  Eigen::VectorXd u0;      // where it started
  Eigen::VectorXd best_u;  // its best point
  double best_value = kNaN;
  int evaluations = 0;
  std::string result;  // NLopt's result (e.g. "FTOL_REACHED") or Ceres' termination message
};

struct OptimizerSummary {
  std::string algorithm;
  Termination termination = Termination::kFailure;
  std::string message;
  std::vector<std::string> names;   // coordinate names
  Evaluation initial;               // at the start point
  Evaluation best;                  // the best feasible evaluation
  std::vector<Evaluation> history;  // every evaluation, in order
  std::vector<int> history_start;   // per evaluation: which start (0 .. starts - 1)
  std::vector<StartRecord> starts;
  int cache_hits = 0;     // points asked for twice (answered from the history, not re-run)
  int replayed = 0;       // evaluations served from OptimizerOptions::replay
  double fd_step = kNaN;  // Ceres: the central-difference step used (unit coordinates)
  // Ceres with the step chosen (fd_step = 0) when even the largest step left the Jacobian
  // noise-dominated (least_squares.hpp, StepChoice): the factor its Gauss-Newton steps were
  // shortened by (below 0.8); NaN otherwise.
  double fd_shrink = kNaN;
  double wall_time_s = 0;

  int evaluations() const { return static_cast<int>(history.size()); }
  bool IsSolutionUsable() const { return best.feasible && std::isfinite(best.value); }
  std::string BriefReport() const;  // one line
  std::string FullReport() const;   // several lines, per parameter and per start
};

// The start points: options.start (or the scene's table), clamped to the unit cube, then the
// starts - 1 points of the design.
std::vector<Eigen::VectorXd> StartPoints(const Objective& objective,
                                         const OptimizerOptions& options);

}  // namespace talus::calibration
