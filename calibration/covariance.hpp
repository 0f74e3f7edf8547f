#pragma once
// The covariance of the fitted parameters at the optimum, on top of the Evaluator (evaluator.hpp):
// the Jacobian's central differences reuse a calibration's evaluations (its history) and run only
// the points it lacks, through the same cache the optimisers use.
//
// Uncertainty. The fit minimises f(u) = sum_i r_i(u)^2, a sum of proper scores over independent
// runs -- an M-estimator, not a Gaussian likelihood, so (J^T J)^-1 alone has no scale. Its
// covariance is the sandwich H^-1 V H^-1 (e.g. Huber 1967; White 1982) with H = 2 J^T J, the
// Gauss-Newton Hessian of f, and V = sum_g g_g g_g^T the spread of the runs' score gradients
// g_g = 2 J_g^T r_g (J_g, r_g: the rows of run g, Objective::residual_groups; the prior's rows
// belong to no run), times G / (G - n) for G runs and n coordinates. ceres::Covariance gives
// (J^T J)^-1 at the optimum (dense SVD), and the covariance is (J^T J)^-1 M (J^T J)^-1 with
// M = sum_g (J_g^T r_g)(J_g^T r_g)^T. A prior (objective.hpp) adds its rows to J^T J and, as
// pseudo-observations whose stated mean is uncertain by its sd, w J_p^T J_p to M: a coordinate
// that only its prior holds (its profile flat) is kept, and gets the prior's sd; one the runs
// hold gets the combination of both. Where J^T J is rank-deficient, Ceres refuses: each
// parameter is then profiled (ProfileParameters) and those whose profile is flat are held
// constant (a ceres::SubsetManifold) for the covariance of the others, and reported unidentified.
// Profiles measured beforehand (UncertaintyOptions::profiles) are used the same way from the
// start: a flat profile overrules a finite-difference Jacobian of noise.
//
// Stationarity. The sandwich linearises about a stationary point, but on a rough objective the
// optimiser stops in a dip of the rocks' noise, where the objective smoothed over the
// covariance's step still has a slope: Levenberg-Marquardt's and BOBYQA's trial steps out of the
// dip are rejected on the rough values. The Gauss-Newton step at that step,
// d = -(J^T J)^-1 J^T rbar = -H^-1 f'_h (f'_h the objective's central difference over +-h,
// rbar the mean of the residuals there, so J^T rbar = f'_h / 2; the same evaluations as J),
// points from the fit to the stationary point of the smoothed model. Its distance is an error
// the sandwich cannot see, and is added to the covariance as d d^T (the sandwich's uncentred
// meat already holds d d^T / G of it: at most a factor 1 + 1/G too wide in that term). Measured
// on 24 runs of 5 rocks, whose fit moves by sd 0.043 with the model's seed: the offsets were
// -0.057 and -0.078 where the fit lay 0.11 from the truth. Two limits (docs/calibration.md,
// "Stationarity"):
//  - the slope was measured over u -+ h only: a longer step is shortened to that stencil (its
//    largest coordinate h, its direction kept) rather than extrapolated, which along a valley of
//    correlated parameters runs to a corner of the box (Tschamut's four parameters,
//    correlations 0.73-0.97: up to 0.55 of a range at h = 0.163);
//  - only where the differences resolve the gradient (UncertaintyOptions::gradient_resolved):
//    where they are noise-dominated d is the noise's too (two correlated parameters: steps of
//    0.13 and 0.20 of the ranges from a fit 0.005 from the truth), and the stationary point is
//    not located.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/objective.hpp"
#include "calibration/roughness.hpp"

namespace talus::calibration {

struct UncertaintyOptions {
  // Central-difference step, unit coordinates. A calibration chooses it at the optimum by the
  // rule of the Ceres fit (ChooseFiniteDifferenceStep, least_squares.hpp) unless it is given.
  double fd_step = 0.01;
  // Ceres' Covariance::Options::min_reciprocal_condition_number: smaller eigenvalues of J^T J
  // (relative to the largest) make it rank-deficient.
  double min_reciprocal_condition_number = 1e-10;
  // A parameter whose standard error exceeds this fraction of its range (unit coordinates) is
  // reported as weakly constrained: its +-2 sigma interval does not fit in the box.
  double weak_fraction = 0.25;
  // For the profile fallback: the objective's noise level (RoughnessReport::level()), and the
  // profiles' options.
  double noise = 0;
  ProfileOptions profile;
  // Whether the difference quotients at fd_step resolve the gradient (StepChoice::noise_dominated
  // false, least_squares.hpp). Where they do not, the Gauss-Newton step below is the noise's, and
  // the stationary point is not located (no d d^T).
  bool gradient_resolved = true;
  // Profiles already measured at this point (ProfileParameters, one per coordinate), or empty.
  // A coordinate whose profile is flat is unidentified whatever J says -- on a rough objective
  // the differences of a parameter that only reshuffles which way rocks turn are noise, which a
  // covariance would read as information -- and is held constant like a rank-deficient one.
  std::vector<ParameterProfile> profiles;
  bool IsValid(std::string* why) const;
};

struct Uncertainty {
  bool computed = false;        // a covariance was computed (for the identified parameters)
  bool rank_deficient = false;  // J^T J was rank-deficient: profiles decided what is identified
  std::vector<std::string> names;
  Eigen::VectorXd u;         // where (unit coordinates)
  Eigen::VectorXd values;    // the parameters there
  double fd_step = 0;        // the central-difference step it used, unit coordinates
  Eigen::MatrixXd jacobian;  // residuals x coordinates, unit coordinates
  Eigen::VectorXd residuals;
  int groups = 0;                   // independent groups (runs) in the sandwich
  Eigen::MatrixXd covariance_unit;  // n x n, unit coordinates; rows of unidentified ones are 0
  Eigen::MatrixXd covariance;       // n x n, physical units (through the transforms' Jacobian)
  Eigen::VectorXd standard_error;   // physical units; NaN where unidentified
  Eigen::VectorXd standard_error_unit;
  Eigen::MatrixXd correlation;  // NaN where unidentified
  // d, the Gauss-Newton step at fd_step from u to the smoothed model's stationary point (unit
  // coordinates, kept inside the box; 0 where unidentified), and the parameters at u + d. Its
  // d d^T is part of covariance_unit. Only where `stationary_located` (a covariance computed with
  // a resolved gradient); else d = 0 and the values NaN.
  bool stationary_located = false;
  bool offset_limited = false;  // d was shortened to the stencil (its largest coordinate fd_step)
  Eigen::VectorXd offset_unit;
  Eigen::VectorXd stationary_values;
  std::vector<bool> identified;            // per coordinate
  std::vector<bool> weak;                  // identified but standard_error_unit > weak_fraction
  std::vector<ParameterProfile> profiles;  // when rank-deficient
  std::string note;                        // the identifiability note, naming parameters
  int evaluations = 0;
  double wall_time_s = 0;
  std::string Report() const;  // a few lines for people
};

// The covariance at u (the optimum). `known` evaluations (a calibration's history) are reused
// instead of re-running their points. Throws what the objective throws.
Uncertainty EstimateUncertainty(const Objective& objective, const Eigen::VectorXd& u,
                                const UncertaintyOptions& options,
                                const std::vector<Evaluation>& known = {});

}  // namespace talus::calibration
