#pragma once
// Calibration by NLopt's derivative-free methods on the objective (objective.hpp), in the unit
// cube: local BOBYQA and Sbplx, global CRS2-LM, DIRECT-L and ISRES, chosen by name; optionally
// from several starts (the given start, then Sobol or Latin-hypercube points). Every evaluation is
// kept. The result is a Summary with a termination type, a brief and a full report (Ceres style).
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

// The algorithms by name: "bobyqa", "sbplx" (local), "crs2_lm", "direct_l", "isres" (global).
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
  // Called after every evaluation (on the calling thread); may throw to stop (e.g. interrupted):
  // the optimiser stops and the exception comes out of Calibrate.
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
  std::string nlopt_result;  // e.g. "FTOL_REACHED"
};

struct Summary {
  std::string algorithm;
  Termination termination = Termination::kFailure;
  std::string message;
  std::vector<std::string> names;   // coordinate names
  Evaluation initial;               // at the start point
  Evaluation best;                  // the best feasible evaluation
  std::vector<Evaluation> history;  // every evaluation, in order
  std::vector<int> history_start;   // per evaluation: which start (0 .. starts - 1)
  std::vector<StartRecord> starts;
  int cache_hits = 0;  // points NLopt asked for twice (answered from the history, not re-run)
  double wall_time_s = 0;

  int evaluations() const { return static_cast<int>(history.size()); }
  bool IsSolutionUsable() const { return best.feasible && std::isfinite(best.value); }
  std::string BriefReport() const;  // one line
  std::string FullReport() const;   // several lines, per parameter and per start
};

// Minimises the objective. Throws what options.on_evaluation throws; std::invalid_argument for
// invalid options (validate them first).
Summary Calibrate(const Objective& objective, const OptimizerOptions& options);

}  // namespace talus::calibration
