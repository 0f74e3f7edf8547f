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
  double fd_step = 0;         // the central-difference step it used, unit coordinates
  Eigen::MatrixXd jacobian;  // residuals x coordinates, unit coordinates
  Eigen::VectorXd residuals;
  int groups = 0;                   // independent groups (runs) in the sandwich
  Eigen::MatrixXd covariance_unit;  // n x n, unit coordinates; rows of unidentified ones are 0
  Eigen::MatrixXd covariance;       // n x n, physical units (through the transforms' Jacobian)
  Eigen::VectorXd standard_error;   // physical units; NaN where unidentified
  Eigen::VectorXd standard_error_unit;
  Eigen::MatrixXd correlation;             // NaN where unidentified
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
