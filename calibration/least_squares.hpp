#pragma once
// The Ceres back-end of the calibration's optimiser (optimizer.hpp): Ceres Solver on the residual
// vector (Evaluation::residuals, objective.hpp), bounded nonlinear least squares in the unit cube.
// The covariance of the fitted parameters is in covariance.hpp.
//
// Derivatives are central differences with an absolute step h in unit coordinates (a fraction of
// each parameter's range), chosen from the Jacobian's measured noise and curvature
// (ChooseFiniteDifferenceStep below): a smaller step would differentiate the noise of which way
// rocks turn. At a bound the pair of points moves inside the box (one-sided there;
// residual_cost.hpp).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calibration/covariance.hpp"
#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"

namespace talus::calibration {

// The central-difference step of the Gauss-Newton Jacobian on a rough objective. With residuals
// r(u) = r_smooth(u) + e(u), e the noise of which way rocks turn, the difference quotient over a
// stencil of width w (2h inside the box) has E[(J^T J)_jj] = S_j + N_j / w^2: S_j =
// |d r_smooth / d u_j|^2 is the curvature Gauss-Newton needs (f'' ~ 2 S), N_j = sum_i
// Var(e_i(u + h) - e_i(u - h)) the noise of the difference (variances over release seeds). Both
// points run on one release seed (common random numbers, as in the calibration's own Jacobians), so
// N_j is less than the 2 sum_i s_i^2 of independent points (s_i^2 residual i's variance) and grows
// with w as fewer rocks keep their paths. The noise term inflates J^T J, so the Gauss-Newton step
// -(J^T J)^-1 J^T r shrinks by 1 / (1 + N / (S w^2)) and Levenberg-Marquardt stalls where the step
// falls below its parameter tolerance. Measuring (J^T J)_jj at two widths gives S_j and N_j (two
// equations, N_j taken equal at both; with x = 1 / w^2 the measured N_j is
// (x1 N_j(w1) - x2 N_j(w2)) / (x1 - x2) in expectation); the step is the smallest h with
// N_j / (2h)^2 <= noise_share * S_j for every coordinate, within [small, max_step]. Where the
// difference's noise grows between the two widths, S_j absorbs the growth,
// x1 x2 (N_j(w2) - N_j(w1)) / (x1 - x2): on the Tyrol run-outs S was 0.45 from h = 0.05 and 0.2 (a
// scan along the coordinate gave 0.4 to 0.6) but 1.2 from 0.01 and 0.2. On the scar lengths of
// tests/calibration/recovery_test.cpp at their start, over 24 other seeds, the difference's noise
// was 0.044 at w 0.1 and 0.112 at 0.26 (independent points': 0.32); the step choice's N was 0.042
// over 8 seeds against the expected 0.032, its S 1.2 against squared mean quotients of 0.06 to 0.2.
// The objective is flat there, so S, and whether the step is noise-dominated, follow the release
// seed (6 of 12 seeds noise-dominated). When even max_step leaves the noise term above that share,
// the step is max_step and `noise_dominated` is set: Gauss-Newton steps are shortened by shrink()
// and Ceres may stop short of the optimum by its parameter tolerance; more rocks per run lower N.
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

// The covariance's central-difference step at u (a fit's optimum): options.fd_step when it is
// given (> 0), else ChooseFiniteDifferenceStep's at u, which also sets options.gradient_resolved.
// Chosen at the optimum, not taken from the start: near the optimum the residuals' trend is small
// against the ensemble's noise, and a step chosen where the trend was large reads noise as
// curvature (J^T J = S + N / w^2), which shrinks the stated standard error (docs/calibration.md,
// "Ceres and the uncertainty"). Returns the choice's report ("" when the step was given).
std::string ChooseCovarianceStep(const Objective& objective, const Eigen::VectorXd& u,
                                 UncertaintyOptions& options);

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

}  // namespace talus::calibration
