#pragma once
// The bootstrap over runs: a second estimate of the fitted parameters' uncertainty, beside the
// sandwich covariance (covariance.hpp), which can understate it on a rough objective.
//
// The objective is a sum over independent groups -- the runs, and each observation of the whole
// scene --, f(u) = sum_g S_g(u) + prior(u), S_g the sum of the squared residuals of group g
// (Objective::residual_groups; its scores as they enter f). A resample draws G groups with
// replacement (seeded) and counts group g m_g times: f_b(u) = sum_g m_g S_g(u) + prior(u), the
// objective of a data set that holds run g m_g times (each kind's mean keeps the full data's
// count as its denominator, so one observation per run gives exactly the mean over the resample).
// Each resample is refitted by BOBYQA from a start near the optimum (start_spread) with a bounded
// budget; the spread of the B refits gives standard errors, percentile intervals and correlations (Efron & Tibshirani 1993,
// ch. 6 and 13).
//
// The rocks of an evaluation do not depend on the weights: one evaluation at u gives every
// resample's f_b(u). The per-group sums are therefore cached by u (exactly: the same bits of u),
// and the refits share the points they have in common (BOBYQA's first 2n + 1 points are the same
// for every resample). With a `resolution` h > 0 the refits evaluate f_b on the lattice
// u_opt + h k (k integer, clamped to the box): a point BOBYQA asks for is rounded to its nearest
// lattice point, so refits that wander near each other share their evaluations and the cost grows
// far more slowly than B. Choose h at the objective's resolution, the step above its measured
// roughness (roughness.hpp): differences below it are the ensemble's noise, not information, and
// a refit could not resolve them anyway. h = 0 evaluates exactly where BOBYQA asks.
// Refits run one after the other, each evaluation with the objective's threads, so the result is
// bit-identical for any thread count and for a resumed calibration.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "calibration/objective.hpp"
#include "calibration/roughness.hpp"

namespace talus::calibration {

struct BootstrapOptions {
  int resamples = 0;  // B; 0: no bootstrap
  // Evaluations each refit may ask for (answered from the cache or run); 0: 10 (n + 2) for n
  // refitted coordinates.
  int refit_evaluations = 0;
  double initial_step = 0.05;  // BOBYQA's first step, unit coordinates
  double xtol_abs = 1e-3;      // a refit stops when every step is below this (unit coordinates)
  double ftol_rel = 1e-4;      // ... or f_b changes relatively by less
  double resolution = 0;       // lattice spacing h of the refits, unit coordinates; 0: none
  std::uint64_t seed = 1;      // the resampling
  // Each refit starts at a lattice point drawn uniformly within +- start_spread (unit
  // coordinates) of the optimum, seeded by (seed, resample), instead of at the optimum: refits
  // that all start in the dip of a rough objective where the fit stopped stay in it, and their
  // spread understates the uncertainty (docs/calibration.md, "Limits"). 0: from the optimum.
  // Measured on the recovery problems (tests/calibration/recovery_test.cpp), 0.1 widened the
  // bootstrap's standard error from 0.02-0.04 to 0.058-0.068, near the data's 0.067-0.086.
  double start_spread = 0.1;
  double level = 0.95;         // of the percentile intervals
  // Profiles measured at the optimum (ProfileParameters, one per coordinate), or empty: a
  // coordinate with a flat profile is held at the optimum and gets no interval (unidentified).
  std::vector<ParameterProfile> profiles;

  static constexpr int kMaxResamples = 100000;
  bool IsValid(std::string* why) const;
};

struct Bootstrap {
  int resamples = 0;
  int groups = 0;  // G, the independent groups (runs) resampled
  double level = 0.95;
  std::vector<std::string> names;
  double resolution = 0;
  double start_spread = 0;  // of the refits' starts (BootstrapOptions::start_spread)
  std::uint64_t seed = 1;
  std::vector<bool> identified;         // per coordinate: refitted (not held for a flat profile)
  Eigen::VectorXd u;                    // the optimum the refits start from (unit coordinates)
  Eigen::MatrixXd refits;               // B x n: each resample's fitted values (physical units)
  Eigen::MatrixXd refits_unit;          // B x n: the same in unit coordinates
  Eigen::VectorXd standard_error;       // sd of the refits, physical units; NaN if unidentified
  Eigen::VectorXd standard_error_unit;  // the same in unit coordinates
  Eigen::VectorXd lower, upper;         // percentile interval at `level`, physical units
  Eigen::MatrixXd correlation;          // of the refits' unit coordinates; NaN if unidentified
  int refits_at_budget = 0;             // refits that spent their budget before converging
  int evaluations = 0;                  // evaluations run (not answered from the cache)
  int cached = 0;                       // evaluations answered from the cache
  double wall_time_s = 0;
  std::string note;
  std::string Report() const;  // a few lines for people
};

// The resampling counts: B x G, row b holding how often each group is drawn (rows sum to G).
Eigen::MatrixXi ResampleCounts(int resamples, int groups, std::uint64_t seed);

// The bootstrap at u (the optimum). `known` evaluations (a calibration's history) fill the cache
// first. Throws what the objective throws, and std::invalid_argument for invalid options.
Bootstrap BootstrapOverRuns(const Objective& objective, const Eigen::VectorXd& u,
                            const BootstrapOptions& options,
                            const std::vector<Evaluation>& known = {});

// A refit of f by BOBYQA from `origin` (unit coordinates) over the coordinates `free`, the others
// held, with the options' first step and tolerances, on the lattice origin + resolution k (clamped
// to [0, 1]), within `budget` evaluations of f; the refitted point, on the lattice. `at_budget`:
// whether the budget ended it. The bootstrap's refits and the seed refits (seeds.hpp) are these.
// `start` (when given): where BOBYQA starts instead of `origin`, which stays the lattice's origin.
Eigen::VectorXd RefitFromOptimum(const std::function<double(const Eigen::VectorXd&)>& f,
                                 const std::vector<int>& free, const Eigen::VectorXd& origin,
                                 const BootstrapOptions& options, int budget, bool* at_budget,
                                 const Eigen::VectorXd* start = nullptr);

// The evaluations each refit of `refitted` coordinates may ask for: the options' or 10 (n + 2).
int RefitBudget(const BootstrapOptions& options, int refitted);

// The sample standard deviation (denominator size - 1) of at least two values.
double SampleSd(const Eigen::VectorXd& x);

}  // namespace talus::calibration
