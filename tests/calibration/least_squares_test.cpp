// The Ceres back-end's finite-difference step (ChooseFiniteDifferenceStep) on synthetic
// objectives whose curvature S_j = |d r / d u_j|^2 and noise N_j = 2 sum_i s_i^2 are known (no
// rock runs: linear_problem.hpp), and OptimizeLeastSquares on a linear least-squares problem whose
// minimiser is known in closed form.

#include "calibration/least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "linear_problem.hpp"

namespace talus::calibration {
namespace {

using testing::Free;
using testing::GroundValues;
using testing::LinearProblem;
using testing::NoiseAt;

// mu_min in [0.2, 0.8] and mu_max in [1, 3]: unit coordinates u1 = (mu_min - 0.2) / 0.6,
// u2 = (mu_max - 1) / 2.
double U1(const GroundValues& v) { return (v.mu_min - 0.2) / 0.6; }
double U2(const GroundValues& v) { return (v.mu_max - 1.0) / 2.0; }

// 400 runs; along u1 each residual rises by 0.05 (S_1 = 400 * 0.05^2 = 1) with noise of sd
// s = 3.54e-3 independent between points (N_1 = 2 * 400 s^2 = 0.01); along u2 each rises by 0.1
// with a curvature 0.3 (u2 - 0.5)^2 and no noise (S_2 = 400 * 0.1^2 = 4 at u2 = 0.5, N_2 = 0).
// The step is the smallest h with N / (2h)^2 <= 0.25 S: h = sqrt(N / (0.25 S)) / 2 = 0.1, from the
// noisy coordinate. Estimated from one draw of the noise at each of the 4 stencil points: the
// difference quotients' noise sums 400 terms (about 5 % relative error) and the cross term of
// signal and noise is about 0.1 at w = 0.1 against D = 2, giving N to about 12 % and S to about
// 3 % (one standard error); tolerances: 30 % on N, 10 % on S, 15 % on the step.
TEST(ChooseFiniteDifferenceStep, RecoversKnownNoiseAndCurvature) {
  const int groups = 400;
  const double s = std::sqrt(0.01 / (2.0 * groups));
  LinearProblem problem(groups);
  const Objective objective = problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kMuMax, 1.0, 3.0)},
      [s](const GroundValues& v, int g) {
        const double u2 = U2(v);
        return 0.05 * U1(v) + s * NoiseAt(v.mu_min, g) + 0.1 * u2 + 0.3 * (u2 - 0.5) * (u2 - 0.5) - 0.1;
      });
  const Eigen::Vector2d u(0.5, 0.5);
  const StepChoice choice = ChooseFiniteDifferenceStep(objective, u);
  EXPECT_EQ(choice.evaluations, 1 + 4 * 2);
  ASSERT_EQ(choice.signal.size(), 2u);
  EXPECT_NEAR(choice.signal[0], 1.0, 0.10);
  EXPECT_NEAR(choice.noise[0], 0.01, 0.3 * 0.01);
  // No noise: both widths see the same exact central difference (a quadratic's is exact).
  EXPECT_NEAR(choice.signal[1], 4.0, 1e-9);
  EXPECT_NEAR(choice.noise[1], 0.0, 1e-12);
  EXPECT_NEAR(choice.step, 0.1, 0.015);
  EXPECT_FALSE(choice.noise_dominated);
  // At the chosen step N / (S w^2) is 0.25 by construction: steps shortened to 0.8.
  EXPECT_NEAR(choice.shrink(), 0.8, 1e-9);
  const std::string report = choice.Report();
  EXPECT_NE(report.find("coordinate 0: J^T J = "), std::string::npos) << report;
  EXPECT_NE(report.find("coordinate 1: J^T J = "), std::string::npos) << report;
  EXPECT_EQ(report.find("noise-dominated"), std::string::npos) << report;
}

// A smooth objective keeps the smaller measured step; one whose noise needs h above max_step
// gets max_step, is flagged noise-dominated, and its Gauss-Newton steps are shortened by
// 1 / (1 + N / (S w^2)) at w = 2 max_step. Here S = 400 * 0.05^2 = 1 and N = 2 * 400 * 0.025^2
// = 0.5, so h = sqrt(0.5 / 0.25) / 2 = 0.71 and the shrink is 1 / (1 + 0.5 / 0.25) = 1/3. One draw
// of the noise gives N to about 6 % and S, the difference of two noise-inflated quotients, to
// about 26 % (one standard error): tolerances 20 % on N, 50 % on S.
TEST(ChooseFiniteDifferenceStep, SmoothKeepsTheSmallStepNoisyIsCappedAndFlagged) {
  const int groups = 400;
  LinearProblem problem(groups);
  const Objective smooth = problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                                        [](const GroundValues& v, int g) {
                                          return (g % 2 ? 0.02 : -0.01) * U1(v) + 0.001 * g;
                                        });
  const StepChoice clear = ChooseFiniteDifferenceStep(smooth, Eigen::VectorXd::Constant(1, 0.4));
  EXPECT_EQ(clear.step, StepChoiceOptions{}.small);
  EXPECT_FALSE(clear.noise_dominated);
  EXPECT_NEAR(clear.signal[0], 200 * (0.02 * 0.02 + 0.01 * 0.01), 1e-9);
  EXPECT_NEAR(clear.shrink(), 1.0, 1e-9);

  const Objective noisy = problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                                       [](const GroundValues& v, int g) {
                                         return 0.05 * U1(v) + 0.025 * NoiseAt(v.mu_min, g);
                                       });
  const StepChoice capped = ChooseFiniteDifferenceStep(noisy, Eigen::VectorXd::Constant(1, 0.5));
  EXPECT_TRUE(capped.noise_dominated);
  EXPECT_EQ(capped.step, StepChoiceOptions{}.max_step);
  EXPECT_NEAR(capped.noise[0], 0.5, 0.2 * 0.5);
  EXPECT_NEAR(capped.signal[0], 1.0, 0.5);
  const double w = 2 * capped.step;
  EXPECT_NEAR(capped.shrink(), 1 / (1 + capped.noise[0] / (capped.signal[0] * w * w)), 1e-12);
  EXPECT_LT(capped.shrink(), 0.8);
  EXPECT_NE(capped.Report().find("noise-dominated"), std::string::npos);
}

// At a bound the stencil is one-sided (width h, not 2h): a linear objective's slope is still
// measured exactly there.
TEST(ChooseFiniteDifferenceStep, AtABoundTheOneSidedStencilMeasuresTheSlope) {
  LinearProblem problem(10);
  const Objective objective = problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8)},
      [](const GroundValues& v, int g) { return 0.3 * U1(v) - 0.01 * g; });
  for (double u0 : {0.0, 1.0}) {
    const StepChoice choice = ChooseFiniteDifferenceStep(objective, Eigen::VectorXd::Constant(1, u0));
    EXPECT_NEAR(choice.signal[0], 10 * 0.09, 1e-9) << u0;
    EXPECT_EQ(choice.step, StepChoiceOptions{}.small) << u0;
    EXPECT_EQ(choice.evaluations, 3) << u0 << ": u itself stands in for the side beyond the bound";
  }
}

// An infeasible point (outside the unit cube) has nothing to measure: the large step, after one
// evaluation. Invalid options throw std::invalid_argument naming the option and its value.
TEST(ChooseFiniteDifferenceStep, InfeasiblePointAndInvalidOptions) {
  LinearProblem problem(4);
  const Objective objective = problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8)}, [](const GroundValues& v, int) { return U1(v); });
  const StepChoice out = ChooseFiniteDifferenceStep(objective, Eigen::VectorXd::Constant(1, 1.5));
  EXPECT_EQ(out.step, StepChoiceOptions{}.large);
  EXPECT_EQ(out.evaluations, 1);
  EXPECT_TRUE(out.signal.empty());

  const auto message = [&](StepChoiceOptions o) {
    try {
      ChooseFiniteDifferenceStep(objective, Eigen::VectorXd::Constant(1, 0.5), o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  StepChoiceOptions o;
  o.small = 0.3;  // not below large
  EXPECT_NE(message(o).find("small = 0.3 and large = 0.2"), std::string::npos) << message(o);
  o = {};
  o.noise_share = 0;
  EXPECT_NE(message(o).find("noise_share = 0 must be > 0"), std::string::npos) << message(o);
  o = {};
  o.max_step = 0.6;
  EXPECT_NE(message(o).find("max_step = 0.6"), std::string::npos) << message(o);
  EXPECT_EQ(message(o).rfind("ChooseFiniteDifferenceStep: ", 0), 0u) << message(o);
  EXPECT_TRUE(StepChoiceOptions{}.IsValid(nullptr));
}

// Linear least squares: residuals r_g = mu_min + mu_max t_g - y_g over 8 runs, whose minimiser is
// the straight-line fit of y on t (normal equations). Levenberg-Marquardt on an exactly linear
// problem reaches it to Ceres' tolerances; the fit is the point where it ended, and each start is
// recorded. The step is measured first (fd_step = 0): noise-free, the small one.
TEST(OptimizeLeastSquares, LinearProblemReachesTheNormalEquationsSolution) {
  const double t[8] = {-1, -0.7, -0.4, -0.1, 0.2, 0.5, 0.8, 1};
  const double y[8] = {-1.4, -0.95, -0.3, 0.35, 0.9, 1.55, 2.2, 2.5};
  LinearProblem problem(8);
  const Objective objective = problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kMuMax, 1.0, 3.0)},
      [&](const GroundValues& v, int g) { return v.mu_min + v.mu_max * t[g] - y[g]; });
  Eigen::MatrixXd x(8, 2);
  Eigen::VectorXd yy(8);
  for (int g = 0; g < 8; ++g) {
    x.row(g) << 1, t[g];
    yy[g] = y[g];
  }
  const Eigen::Vector2d fit = (x.transpose() * x).ldlt().solve(x.transpose() * yy);
  ASSERT_GT(fit[0], 0.2);
  ASSERT_LT(fit[0], 0.8);
  ASSERT_GT(fit[1], 1.0);
  ASSERT_LT(fit[1], 3.0);
  OptimizerOptions options;
  options.algorithm = "ceres";
  options.max_evaluations = 200;
  options.xtol_abs = 1e-10;
  options.ftol_rel = 1e-12;
  options.starts = 2;
  const OptimizerSummary summary = OptimizeLeastSquares(objective, options);
  EXPECT_EQ(summary.algorithm, "ceres");
  EXPECT_EQ(summary.fd_step, StepChoiceOptions{}.small);
  EXPECT_TRUE(std::isnan(summary.fd_shrink));
  ASSERT_TRUE(summary.IsSolutionUsable());
  EXPECT_NEAR(summary.best.values[0], fit[0], 1e-6);
  EXPECT_NEAR(summary.best.values[1], fit[1], 1e-6);
  const double minimum = (x * fit - yy).squaredNorm();
  EXPECT_NEAR(summary.best.value, minimum, 1e-9);
  ASSERT_EQ(summary.starts.size(), 2u);
  for (const StartRecord& s : summary.starts) {
    EXPECT_NEAR(s.best_value, minimum, 1e-9) << s.result;
    EXPECT_GT(s.evaluations, 0);
  }
  EXPECT_EQ(summary.termination, Termination::kConvergence) << summary.message;
  EXPECT_LE(summary.evaluations(), options.max_evaluations);
}

// The evaluation budget stops Levenberg-Marquardt: never more evaluations than allowed, and the
// termination says why.
TEST(OptimizeLeastSquares, StopsAtTheEvaluationBudget) {
  LinearProblem problem(6);
  const Objective objective = problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kMuMax, 1.0, 3.0)},
      [](const GroundValues& v, int g) {
        return std::exp(v.mu_min * (g + 1)) - 0.1 * v.mu_max * v.mu_max * g - 1;
      });
  OptimizerOptions options;
  options.algorithm = "ceres";
  options.fd_step = 0.01;
  options.max_evaluations = 7;
  options.xtol_abs = 1e-14;
  options.ftol_rel = 1e-16;
  const OptimizerSummary summary = OptimizeLeastSquares(objective, options);
  EXPECT_LE(summary.evaluations(), 7);
  EXPECT_EQ(summary.termination, Termination::kMaxEvaluations) << summary.message;
  EXPECT_EQ(summary.fd_step, 0.01);
}

}  // namespace
}  // namespace talus::calibration
