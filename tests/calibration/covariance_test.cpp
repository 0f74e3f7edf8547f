// The sandwich covariance (calibration/covariance.hpp) on linear least-squares problems whose
// covariance is known in closed form (no rock runs: linear_problem.hpp). With residuals linear in
// the parameters the central differences are exact, so EstimateUncertainty must give the
// heteroscedasticity-consistent covariance (X^T X)^-1 X^T diag(e^2) X (X^T X)^-1 G / (G - n)
// (White 1980, "HC1") to round-off; and for the mean of G observations, s^2 / G.

#include "calibration/covariance.hpp"

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

// The mean of G observations: r_g = mu_min - y_g, minimised at the sample mean; the sandwich with
// one residual per run is sum_g r_g^2 / (G (G - 1)) = s^2 / G, the squared standard error of the
// mean. mu_min in [0.2, 0.8]: in unit coordinates the standard error is divided by the range 0.6.
TEST(EstimateUncertainty, MeanOfObservationsHasTheStandardErrorOfTheMean) {
  const double y[10] = {0.41, 0.55, 0.47, 0.62, 0.38, 0.51, 0.58, 0.44, 0.49, 0.60};
  double mean = 0;
  for (double v : y) mean += v / 10;
  double ss = 0;
  for (double v : y) ss += (v - mean) * (v - mean);
  const double se = std::sqrt(ss / 9 / 10);
  LinearProblem problem(10);
  const Objective objective =
      problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                   [&](const GroundValues& v, int g) { return v.mu_min - y[g]; });
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, (mean - 0.2) / 0.6);
  const Uncertainty out = EstimateUncertainty(objective, u, UncertaintyOptions{});
  ASSERT_TRUE(out.computed) << out.note;
  EXPECT_FALSE(out.rank_deficient);
  EXPECT_EQ(out.groups, 10);
  EXPECT_NEAR(out.values[0], mean, 1e-15);
  EXPECT_NEAR(out.standard_error[0], se, 1e-9 * se);
  EXPECT_NEAR(out.standard_error_unit[0], se / 0.6, 1e-9 * se);
  EXPECT_NEAR(out.covariance(0, 0), se * se, 1e-9 * se * se);
  EXPECT_NEAR(out.correlation(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(out.jacobian(0, 0), 0.6, 1e-12);  // d r / d u = the range
  EXPECT_TRUE(out.identified[0]);
  EXPECT_FALSE(out.weak[0]);
  EXPECT_EQ(out.names[0], "medium_hard.mu_min");
  EXPECT_EQ(out.note, "every parameter is constrained by the observations.");
  // u and u +- fd_step: 3 evaluations, none known beforehand.
  EXPECT_EQ(out.evaluations, 3);
  EXPECT_NE(out.Report().find("medium_hard.mu_min"), std::string::npos);
}

// Away from the optimum (a fit stopped in a dip of a rough objective) the objective's slope is
// not zero. For the mean of G observations at mu = mean + d the residuals are linear, so the
// Gauss-Newton step at any step is exact: it goes back to the mean (offset -d / 0.6 in unit
// coordinates) when the stencil holds it, and the covariance is the sandwich with the residuals
// at mu, sum_g (mu - y_g)^2 / (G (G - 1)), plus the offset's square d^2.
TEST(EstimateUncertainty, AFitOffItsStationaryPointHasTheOffsetInItsStandardError) {
  const double y[10] = {0.41, 0.55, 0.47, 0.62, 0.38, 0.51, 0.58, 0.44, 0.49, 0.60};
  double mean = 0;
  for (double v : y) mean += v / 10;
  const double d = 0.04;
  double ss = 0;
  for (double v : y) ss += (mean + d - v) * (mean + d - v);
  const double variance = ss / 9 / 10 + d * d;
  LinearProblem problem(10);
  const Objective objective =
      problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                   [&](const GroundValues& v, int g) { return v.mu_min - y[g]; });
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, (mean + d - 0.2) / 0.6);
  UncertaintyOptions wide;  // a stencil of +-0.1 holds the step, d / 0.6 = 0.067
  wide.fd_step = 0.1;
  const Uncertainty out = EstimateUncertainty(objective, u, wide);
  ASSERT_TRUE(out.computed) << out.note;
  EXPECT_TRUE(out.stationary_located);
  EXPECT_FALSE(out.offset_limited);
  EXPECT_NEAR(out.offset_unit[0], -d / 0.6, 1e-9);
  EXPECT_NEAR(out.stationary_values[0], mean, 1e-9);
  EXPECT_NEAR(out.values[0], mean + d, 1e-15);
  EXPECT_NEAR(out.covariance(0, 0), variance, 1e-9 * variance);
  EXPECT_NEAR(out.standard_error[0], std::sqrt(variance), 1e-9);
  EXPECT_EQ(out.evaluations, 3);  // the slope reuses the Jacobian's points
  EXPECT_NE(out.Report().find("stationary point"), std::string::npos) << out.Report();

  // With the default stencil, +-0.01, the step is shortened to it: an offset of 0.01 of the range.
  const Uncertainty narrow = EstimateUncertainty(objective, u, UncertaintyOptions{});
  ASSERT_TRUE(narrow.computed) << narrow.note;
  EXPECT_TRUE(narrow.offset_limited);
  EXPECT_NEAR(narrow.offset_unit[0], -0.01, 1e-12);
  const double narrow_variance = ss / 9 / 10 + 0.006 * 0.006;
  EXPECT_NEAR(narrow.covariance(0, 0), narrow_variance, 1e-9 * narrow_variance);
  EXPECT_NE(narrow.Report().find("shortened"), std::string::npos) << narrow.Report();

  // At the optimum itself there is no offset.
  const Uncertainty at = EstimateUncertainty(
      objective, Eigen::VectorXd::Constant(1, (mean - 0.2) / 0.6), UncertaintyOptions{});
  EXPECT_TRUE(at.stationary_located);
  EXPECT_NEAR(at.offset_unit[0], 0, 1e-12);

  // Where the differences do not resolve the gradient (noise-dominated), the step is not taken:
  // the plain sandwich, and the report says why.
  UncertaintyOptions unresolved;
  unresolved.gradient_resolved = false;
  const Uncertainty noisy = EstimateUncertainty(objective, u, unresolved);
  ASSERT_TRUE(noisy.computed) << noisy.note;
  EXPECT_FALSE(noisy.stationary_located);
  EXPECT_EQ(noisy.offset_unit[0], 0);
  EXPECT_TRUE(std::isnan(noisy.stationary_values[0]));
  EXPECT_NEAR(noisy.covariance(0, 0), ss / 9 / 10, 1e-9 * variance);
  EXPECT_NE(noisy.Report().find("not located"), std::string::npos) << noisy.Report();
}

// A straight-line fit r_g = mu_min + mu_max t_g - y_g with unequal scatter: the sandwich is HC1,
// computed here from the design matrix X = [1, t] and the residuals e at the least-squares fit;
// covariance, standard errors and the correlation agree to 1e-9 relative.
TEST(EstimateUncertainty, StraightLineFitGivesTheHeteroscedasticityConsistentCovariance) {
  const int g_count = 9;
  const double t[g_count] = {-1, -0.75, -0.5, -0.25, 0, 0.25, 0.5, 0.75, 1};
  const double y[g_count] = {-1.45, -1.1, -0.4, 0.05, 0.55, 0.95, 1.6, 1.85, 2.7};
  LinearProblem problem(g_count);
  const Objective objective =
      problem.Make({Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kMuMax, 1.0, 3.0)},
                   [&](const GroundValues& v, int g) { return v.mu_min + v.mu_max * t[g] - y[g]; });
  Eigen::MatrixXd x(g_count, 2);
  Eigen::VectorXd yy(g_count);
  for (int g = 0; g < g_count; ++g) {
    x.row(g) << 1, t[g];
    yy[g] = y[g];
  }
  const Eigen::MatrixXd xtx_inv = (x.transpose() * x).inverse();
  const Eigen::Vector2d fit = xtx_inv * x.transpose() * yy;
  const Eigen::VectorXd e = x * fit - yy;
  const Eigen::MatrixXd hc1 = xtx_inv * x.transpose() * e.cwiseAbs2().asDiagonal() * x * xtx_inv *
                              (double(g_count) / (g_count - 2));
  const Eigen::Vector2d u((fit[0] - 0.2) / 0.6, (fit[1] - 1.0) / 2.0);
  ASSERT_TRUE((u.array() > 0.1).all() && (u.array() < 0.9).all()) << u.transpose();
  const Uncertainty out = EstimateUncertainty(objective, u, UncertaintyOptions{});
  ASSERT_TRUE(out.computed) << out.note;
  for (int j = 0; j < 2; ++j)
    for (int k = 0; k < 2; ++k)
      EXPECT_NEAR(out.covariance(j, k), hc1(j, k), 1e-9 * hc1.norm()) << j << ", " << k;
  EXPECT_NEAR(out.standard_error[1], std::sqrt(hc1(1, 1)), 1e-9 * std::sqrt(hc1(1, 1)));
  EXPECT_NEAR(out.covariance_unit(0, 1), hc1(0, 1) / (0.6 * 2.0), 1e-9 * hc1.norm());
  const double rho = hc1(0, 1) / std::sqrt(hc1(0, 0) * hc1(1, 1));
  EXPECT_NEAR(out.correlation(0, 1), rho, 1e-9);
  EXPECT_NEAR(out.correlation(1, 0), rho, 1e-9);
  EXPECT_NE(out.Report().find("correlations:"), std::string::npos);
}

// A parameter the residuals do not depend on (beta) makes J^T J rank-deficient: its profile is
// flat, it is reported unidentified (NaN standard error, named in the note), and the covariance
// of the others is the one without it (the mean's s^2 / G).
TEST(EstimateUncertainty, AParameterWithoutEffectIsUnidentifiedAndNamed) {
  const double y[6] = {0.45, 0.52, 0.61, 0.39, 0.50, 0.56};
  double mean = 0;
  for (double v : y) mean += v / 6;
  double ss = 0;
  for (double v : y) ss += (v - mean) * (v - mean);
  LinearProblem problem(6);
  const Objective objective =
      problem.Make({Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kBeta, 50, 500)},
                   [&](const GroundValues& v, int g) { return v.mu_min - y[g]; });
  const Eigen::Vector2d u((mean - 0.2) / 0.6, 0.5);
  const Uncertainty out = EstimateUncertainty(objective, u, UncertaintyOptions{});
  EXPECT_TRUE(out.rank_deficient);
  ASSERT_TRUE(out.computed) << out.note;
  EXPECT_TRUE(out.identified[0]);
  EXPECT_FALSE(out.identified[1]);
  EXPECT_TRUE(std::isnan(out.standard_error[1]));
  EXPECT_TRUE(std::isnan(out.correlation(0, 1)));
  EXPECT_EQ(out.covariance_unit(1, 1), 0.0);
  EXPECT_NEAR(out.standard_error[0], std::sqrt(ss / 5 / 6), 1e-9);
  ASSERT_EQ(out.profiles.size(), 2u);
  EXPECT_EQ(out.profiles[1].range, 0.0);
  EXPECT_NE(out.note.find("not constrained by the observations (flat profile): medium_hard.beta"),
            std::string::npos)
      << out.note;
  EXPECT_NE(out.Report().find("UNIDENTIFIED"), std::string::npos);

  // The same decision from profiles given beforehand: no profiling, the flat one held constant.
  UncertaintyOptions given;
  given.profiles = out.profiles;
  const Uncertainty again = EstimateUncertainty(objective, u, given);
  EXPECT_FALSE(again.rank_deficient);
  EXPECT_FALSE(again.identified[1]);
  EXPECT_NEAR(again.standard_error[0], out.standard_error[0], 1e-12);
  EXPECT_LT(again.evaluations, out.evaluations);
}

// Too few runs for the parameters (G <= n), a weakly constrained parameter (standard error above
// weak_fraction of its range), one at a bound and one within the finite-difference step of a bound
// are each stated in the note.
TEST(EstimateUncertainty, NotesStateTooFewRunsWeakParametersAndBounds) {
  {
    LinearProblem problem(2);
    const Objective objective = problem.Make(
        {Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kMuMax, 1.0, 3.0)},
        [](const GroundValues& v, int g) { return v.mu_min + (g ? 1 : -1) * v.mu_max - 0.3 * g; });
    const Uncertainty out =
        EstimateUncertainty(objective, Eigen::Vector2d(0.5, 0.5), UncertaintyOptions{});
    EXPECT_FALSE(out.computed);
    EXPECT_EQ(out.note, "No covariance: 2 runs with a score gradient for 2 parameters.");
    EXPECT_TRUE(std::isnan(out.standard_error[0]));
  }
  {
    // Observations spread over 1.2 around 0.5: s / sqrt(G) = 0.35 of the range 0.6 > 0.25.
    const double y[4] = {-0.1, 0.3, 0.7, 1.1};
    LinearProblem problem(4);
    const Objective objective =
        problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                     [&](const GroundValues& v, int g) { return v.mu_min - y[g]; });
    const Uncertainty out =
        EstimateUncertainty(objective, Eigen::VectorXd::Constant(1, 0.5), UncertaintyOptions{});
    ASSERT_TRUE(out.computed);
    EXPECT_TRUE(out.weak[0]);
    EXPECT_GT(out.standard_error_unit[0], 0.25);
    EXPECT_NE(out.note.find("weakly constrained (standard error above 0.25 of the range): "
                            "medium_hard.mu_min"),
              std::string::npos)
        << out.note;
    EXPECT_NE(out.Report().find("weak"), std::string::npos);
    const Uncertainty at_bound =
        EstimateUncertainty(objective, Eigen::VectorXd::Constant(1, 0.0), UncertaintyOptions{});
    EXPECT_NE(at_bound.note.find("at a bound (the optimum may lie beyond it; the interval is not "
                                 "reliable): medium_hard.mu_min"),
              std::string::npos)
        << at_bound.note;
    // Within the step (0.01) but not at the bound: said so, not called "at a bound".
    const Uncertainty near =
        EstimateUncertainty(objective, Eigen::VectorXd::Constant(1, 0.005), UncertaintyOptions{});
    EXPECT_EQ(near.note.find("at a bound"), std::string::npos) << near.note;
    EXPECT_NE(near.note.find("within the finite-difference step of a bound (its differences are "
                             "cut short there): medium_hard.mu_min"),
              std::string::npos)
        << near.note;
  }
}

// Evaluations known beforehand (a calibration's history) are reused: with u and u +- fd_step
// known, no point is run again and the result is the same.
TEST(EstimateUncertainty, KnownEvaluationsAreNotRunAgain) {
  LinearProblem problem(5);
  const Objective objective =
      problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                   [](const GroundValues& v, int g) { return v.mu_min - 0.4 - 0.05 * g; });
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.5);
  const Uncertainty fresh = EstimateUncertainty(objective, u, UncertaintyOptions{});
  std::vector<Evaluation> known;
  for (double v : {0.5, 0.49, 0.51})
    known.push_back(objective.Evaluate(Eigen::VectorXd::Constant(1, v)));
  const int before = *problem.runs;
  const Uncertainty reused = EstimateUncertainty(objective, u, UncertaintyOptions{}, known);
  EXPECT_EQ(*problem.runs, before);
  EXPECT_EQ(reused.evaluations, 0);
  EXPECT_EQ(reused.standard_error[0], fresh.standard_error[0]);
}

// Invalid options throw std::invalid_argument naming the option and its bound.
TEST(EstimateUncertainty, InvalidOptionsAreNamed) {
  LinearProblem problem(3);
  const Objective objective = problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                                           [](const GroundValues& v, int) { return v.mu_min; });
  const auto message = [&](UncertaintyOptions o) {
    try {
      EstimateUncertainty(objective, Eigen::VectorXd::Constant(1, 0.5), o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  UncertaintyOptions o;
  o.fd_step = 0.3;
  EXPECT_EQ(message(o),
            "EstimateUncertainty: fd_step = 0.3 must be in (0, 0.25] (a fraction of the range)");
  o = {};
  o.min_reciprocal_condition_number = 1;
  EXPECT_NE(message(o).find("min_reciprocal_condition_number = 1 must be in (0, 1)"),
            std::string::npos);
  o = {};
  o.weak_fraction = 0;
  EXPECT_NE(message(o).find("weak_fraction = 0 must be > 0"), std::string::npos);
  o = {};
  o.noise = -1;
  EXPECT_NE(message(o).find("noise = -1 must be >= 0"), std::string::npos);
  EXPECT_TRUE(UncertaintyOptions{}.IsValid(nullptr));
}

}  // namespace
}  // namespace talus::calibration
