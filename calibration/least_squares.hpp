#pragma once
// Ceres Solver on the calibration's residual vector (Evaluation::residuals, objective.hpp): bounded
// nonlinear least squares in the unit cube, and the covariance of the fitted parameters.
//
// Derivatives are central differences with an absolute step h in unit coordinates (a fraction of
// each parameter's range), chosen from the Jacobian's measured noise and curvature
// (ChooseFiniteDifferenceStep below): a smaller step would differentiate the noise of which way
// rocks turn. At a bound the pair of
// points moves inside the box (one-sided there). Ceres' own NumericDiffCostFunction steps relative
// to |x| and knows no bounds, hence a cost function of our own.
//
// Uncertainty. The fit minimises f(u) = sum_i r_i(u)^2, a sum of proper scores over independent
// runs -- an M-estimator, not a Gaussian likelihood, so (J^T J)^-1 alone has no scale. Its
// covariance is the sandwich H^-1 V H^-1 (e.g. Huber 1967; White 1982) with H = 2 J^T J, the
// Gauss-Newton Hessian of f, and V = sum_g g_g g_g^T the spread of the runs' score gradients
// g_g = 2 J_g^T r_g (J_g, r_g: the rows of run g, Objective::residual_groups; the prior's rows
// belong to no run), times G / (G - n) for G runs and n coordinates. ceres::Covariance gives
// (J^T J)^-1 at the optimum (dense SVD), and the covariance is (J^T J)^-1 M (J^T J)^-1 with
// M = sum_g (J_g^T r_g)(J_g^T r_g)^T. Where J^T J is rank-deficient, Ceres refuses: each
// parameter is then profiled (ProfileParameters) and those whose profile is flat are held
// constant (a ceres::SubsetManifold) for the covariance of the others, and reported unidentified.
// Profiles measured beforehand (UncertaintyOptions::profiles) are used the same way from the
// start: a flat profile overrules a finite-difference Jacobian of noise.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"
#include "calibration/roughness.hpp"

namespace talus::calibration {

// The central-difference step of the Gauss-Newton Jacobian on a rough objective. With residuals
// r(u) = r_smooth(u) + e(u), e the noise of which way rocks turn (variance s_i^2, independent
// between points a step apart), the difference quotient over a stencil of width w (2h inside the
// box) has E[(J^T J)_jj] = S_j + N_j / w^2: S_j = |d r_smooth / d u_j|^2 is the curvature
// Gauss-Newton needs (f'' ~ 2 S), N_j = 2 sum_i s_i^2 the noise. The noise term inflates J^T J, so
// the Gauss-Newton step -(J^T J)^-1 J^T r shrinks by 1 / (1 + N / (S w^2)) and Levenberg-Marquardt
// stalls where the step falls below its parameter tolerance. Measuring (J^T J)_jj at two widths
// gives S_j and N_j (two equations); the step is the smallest h with N_j / (2h)^2 <= noise_share *
// S_j for every coordinate, within [small, max_step]. The model needs the noise of the stencil's
// two points to be independent, which common random numbers break at small steps (few rocks turn
// otherwise): measured on the Tyrol run-outs, S was 0.45 from h = 0.05 and 0.2 (a scan along the
// coordinate gave 0.4 to 0.6) but 1.2 from 0.01 and 0.2. When even max_step leaves the noise term
// above that share, the step is max_step and `noise_dominated` is set: Gauss-Newton steps are
// shortened by shrink() and Ceres may stop short of the optimum by its parameter tolerance; more
// rocks per run lower N.
struct StepChoiceOptions {
  double small = 0.05, large = 0.2;  // the two measured steps h (unit coordinates)
  double noise_share = 0.25;         // largest N / (S w^2) accepted: the step shrinks to 0.8
  double max_step = 0.25;            // as OptimizerOptions::fd_step allows
  bool IsValid(std::string* why) const;
};

struct StepChoice {
  double step = kNaN;                 // the chosen h, unit coordinates
  std::vector<double> signal, noise;  // per coordinate: S_j and N_j as above
  bool noise_dominated = false;       // even max_step leaves the noise above its share
  int evaluations = 0;
  // The factor 1 / (1 + N_j / (S_j w^2)) by which the Gauss-Newton step along coordinate j is
  // shortened at the chosen step (w = 2 step), the smallest over the coordinates.
  double shrink() const;
  std::string Report() const;  // a few lines for people
};

// The step at u, from 1 + 4n evaluations of the objective (not a calibration's history). Throws
// what the objective throws, and std::invalid_argument for invalid options.
StepChoice ChooseFiniteDifferenceStep(const Objective& objective, const Eigen::VectorXd& u,
                                      const StepChoiceOptions& options = {});

// options.algorithm == "ceres": Levenberg-Marquardt with bounds [0, 1] on every coordinate, from
// each start in turn (StartPoints), within the budget of evaluations (each Jacobian costs 2n) and
// time. options.fd_step = 0: the step is ChooseFiniteDifferenceStep's at the first start (its
// evaluations are not in the history); where it finds the Jacobian noise-dominated, the first
// start's Levenberg-Marquardt begins at the minimiser of a response surface (the residuals' linear
// model fitted by least squares to the start and 4 (n + 1) - 1 points of the start design, whose
// evaluations are in the history): a trend that no local difference resolves is resolved there.
// The fit (OptimizerSummary::best) is the best point where a start's Levenberg-Marquardt ended, not
// the best evaluation: on a rough objective the lowest difference point is the lowest draw of
// noise. Called by Optimize, which checks the options.
OptimizerSummary OptimizeLeastSquares(const Objective& objective, const OptimizerOptions& options);

struct UncertaintyOptions {
  double fd_step = 0.01;  // central-difference step, unit coordinates
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
