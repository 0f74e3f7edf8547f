// A parameter's own prior (calibration/parameters.hpp: Prior): its residual, its checks, its term
// in the objective, the fit it moves and the uncertainty it adds, on linear least-squares
// problems whose answers are known in closed form (no rock runs: linear_problem.hpp).
//
// With the data residuals r_g = theta - y_g of G runs (mu_min in [0.2, 0.8], linear: d theta /
// d u = 0.6) and a normal prior (m, sd) of weight w, the objective
//   f(theta) = sum_g (theta - y_g)^2 + w (theta - m)^2 / sd^2
// is smallest at the precision-weighted mean
//   theta* = (sum_g y_g + (w / sd^2) m) / (G + w / sd^2),
// and the sandwich (covariance.hpp) with the prior's pseudo-observation variance gives, in the
// parameter's unit,
//   se^2 = (sum_g (theta* - y_g)^2 G / (G - 1) + w^2 / sd^2) / (G + w / sd^2)^2,
// which falls to the standard error of the mean as w -> 0 and to sd as w / sd^2 -> infinity.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "calibration/calibrate.hpp"
#include "calibration/covariance.hpp"
#include "calibration/least_squares.hpp"
#include "common/error.hpp"
#include "linear_problem.hpp"

namespace talus::calibration {
namespace {

using testing::Free;
using testing::GroundValues;
using testing::LinearProblem;

constexpr double kY[6] = {0.45, 0.52, 0.61, 0.39, 0.50, 0.56};  // mean 0.505

ParameterSpec WithPrior(ParameterSpec spec, Prior prior) {
  spec.prior = prior;
  return spec;
}

std::string Why(const ParameterSpec& spec) {
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  return why;
}

// Normal: the distance from the mean in sds; log-normal: in factors (20 is two factors of 2 above
// 5, 1.25 two below).
TEST(Prior, ResidualIsTheDistanceFromTheMeanInSds) {
  EXPECT_DOUBLE_EQ((Prior{0.3, 0.1, 0}.Residual(0.5)), 2.0);
  EXPECT_DOUBLE_EQ((Prior{0.3, 0.1, 0}.Residual(0.25)), -0.5);
  EXPECT_NEAR((Prior{5, 0, 2}.Residual(20)), 2.0, 1e-15);
  EXPECT_NEAR((Prior{5, 0, 2}.Residual(1.25)), -2.0, 1e-15);
  EXPECT_EQ((Prior{0.3, 0.1, 0}.Describe()), "normal(0.3, sd 0.1)");
  EXPECT_EQ((Prior{5, 0, 2}.Describe()), "log-normal(5, factor 2)");
}

TEST(Prior, NonsenseIsRefusedWithTheReason) {
  const ParameterSpec mu = Free(GroundField::kMuMin, 0.2, 0.8);
  EXPECT_NE(Why(WithPrior(mu, {0.5, 0, 0})).find("give sd (> 0, a normal prior) or factor"),
            std::string::npos);
  EXPECT_NE(Why(WithPrior(mu, {0.5, 0.1, 2})).find("give sd"), std::string::npos);
  EXPECT_NE(Why(WithPrior(mu, {0.5, 0, 0.5})).find("factor = 0.5 must be > 1"), std::string::npos);
  EXPECT_NE(Why(WithPrior(mu, {0.9, 0.1, 0})).find("mean = 0.9 lies outside the bounds [0.2, 0.8]"),
            std::string::npos);
  EXPECT_NE(Why(WithPrior(mu, {NAN, 0.1, 0})).find("must be finite"), std::string::npos);
  ParameterSpec rough;
  rough.block = "a";
  rough.shape_field = ShapeField::kRoughness;
  rough.lower = 0;
  rough.upper = 0.4;
  EXPECT_NE(Why(WithPrior(rough, {0, 0, 2})).find("must be > 0 for a log-normal prior"),
            std::string::npos);
  EXPECT_NE(Why(WithPrior(rough, {0.2, 0, 2})).find("a log-normal prior needs lower > 0"),
            std::string::npos);
  rough.lower = 0.01;
  std::string fine;
  EXPECT_TRUE(WithPrior(rough, {0.2, 0, 2}).IsValid(&fine)) << fine;
  std::string why;
  EXPECT_TRUE(WithPrior(mu, {0.5, 0.1, 0}).IsValid(&why)) << why;
}

// Members of a tie share one coordinate and so one prior: two different ones are refused.
TEST(Prior, ATieTakesOnePrior) {
  const GroundTable table = GroundTable::BuiltIn();
  ParameterSpec a = WithPrior(Free(GroundField::kMuMax, 1, 3), {2, 0.5, 0});
  ParameterSpec b = a;
  a.tie = b.tie = "mu_max_all";
  b.category = "soft";
  const ParameterSet same({a, b}, table);
  ASSERT_TRUE(same.coordinates()[0].prior.has_value());
  EXPECT_EQ(same.coordinates()[0].prior->mean, 2);
  b.prior->sd = 0.4;
  try {
    const ParameterSet two({a, b}, table);
    ADD_FAILURE() << "two priors on one tie accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tie 'mu_max_all' has two priors"), std::string::npos)
        << e.what();
  }
  b.prior.reset();  // one member states it: the tie's
  EXPECT_TRUE(ParameterSet({a, b}, table).coordinates()[0].prior.has_value());
}

// The value is the data term plus w r^2; the residuals (one per run, one per run's spread, then
// one per coordinate with a prior) square to it; a coordinate without a prior adds no residual
// when no reference table is given.
TEST(Prior, ObjectiveAddsTheWeightedSquaredResidual) {
  const double w = 0.06;
  LinearProblem problem(6);
  const Objective objective = problem.Make(
      {WithPrior(Free(GroundField::kMuMin, 0.2, 0.8), {0.6, 0.1, 0}),
       Free(GroundField::kMuMax, 1.0, 3.0)},
      [](const GroundValues& v, int g) { return v.mu_min - kY[g]; }, w);
  ASSERT_EQ(objective.prior_coordinates(), std::vector<int>{0});
  EXPECT_EQ(objective.residual_count(), 6 + 6 + 1);
  const Eigen::Vector2d u((0.53 - 0.2) / 0.6, 0.5);
  const Evaluation e = objective.Evaluate(u);
  double data = 0;
  for (double y : kY) data += (0.53 - y) * (0.53 - y);
  const double prior = w * std::pow((0.53 - 0.6) / 0.1, 2);
  EXPECT_NEAR(e.data, data, 1e-12);
  EXPECT_NEAR(e.prior, prior, 1e-12);
  EXPECT_NEAR(e.value, data + prior, 1e-12);
  EXPECT_NEAR(e.residuals.squaredNorm(), e.value, 1e-12);
  EXPECT_NEAR(e.residuals[12], -std::sqrt(w) * 0.7, 1e-12);
  EXPECT_NEAR(objective.PriorTerm(u), prior, 1e-12);
}

TEST(Prior, APriorWithoutWeightOrAWeightWithoutPriorIsRefused) {
  LinearProblem problem(6);
  const auto residual = [](const GroundValues& v, int g) { return v.mu_min - kY[g]; };
  try {
    problem.Make({WithPrior(Free(GroundField::kMuMin, 0.2, 0.8), {0.6, 0.1, 0})}, residual, 0);
    ADD_FAILURE() << "a prior with prior_weight 0 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("acts only with prior_weight > 0"), std::string::npos)
        << e.what();
  }
  try {
    problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)}, residual, 1.0);
    ADD_FAILURE() << "prior_weight without a prior accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("but no prior"), std::string::npos) << e.what();
  }
}

// The least-squares fit reaches the precision-weighted mean (header): between the data's mean
// 0.505 and the prior's 0.6, at equal precision here (w / sd^2 = 6 = G) halfway, 0.5525.
TEST(Prior, FitReachesThePrecisionWeightedMean) {
  const double w = 0.06, sd = 0.1, m = 0.6;
  LinearProblem problem(6);
  const Objective objective = problem.Make(
      {WithPrior(Free(GroundField::kMuMin, 0.2, 0.8), {m, sd, 0})},
      [](const GroundValues& v, int g) { return v.mu_min - kY[g]; }, w);
  double sum = 0;
  for (double y : kY) sum += y;
  const double expected = (sum + w / (sd * sd) * m) / (6 + w / (sd * sd));
  ASSERT_NEAR(expected, 0.5525, 1e-12);
  OptimizerOptions options;
  options.algorithm = "ceres";
  options.max_evaluations = 100;
  options.xtol_abs = 1e-10;
  options.ftol_rel = 1e-12;
  const OptimizerSummary fit = OptimizeLeastSquares(objective, options);
  ASSERT_TRUE(fit.IsSolutionUsable());
  EXPECT_NEAR(fit.best.values[0], expected, 1e-7);
}

// The sandwich with the prior as a pseudo-observation (header's se^2), to round-off: the
// residuals are linear, so central differences are exact. A second parameter that no run sees
// and only its prior holds gets the prior's sd, and takes no degree of freedom from the runs.
TEST(Prior, UncertaintyCombinesTheRunsAndThePrior) {
  const double w = 0.06, sd = 0.1, m = 0.6;
  LinearProblem problem(6);
  const Objective objective = problem.Make(
      {WithPrior(Free(GroundField::kMuMin, 0.2, 0.8), {m, sd, 0}),
       WithPrior(Free(GroundField::kMuMax, 1.0, 3.0), {2.0, 0.3, 0})},
      [](const GroundValues& v, int g) { return v.mu_min - kY[g]; }, w);
  double sum = 0;
  for (double y : kY) sum += y;
  const double precision = w / (sd * sd);
  const double theta = (sum + precision * m) / (6 + precision);
  double ss = 0;
  for (double y : kY) ss += (theta - y) * (theta - y);
  const double se = std::sqrt(ss * 6 / 5 + w * w / (sd * sd)) / (6 + precision);
  UncertaintyOptions options;
  options.fd_step = 0.01;
  const Uncertainty out =
      EstimateUncertainty(objective, Eigen::Vector2d((theta - 0.2) / 0.6, 0.5), options);
  ASSERT_TRUE(out.computed) << out.note;
  EXPECT_FALSE(out.rank_deficient);
  EXPECT_NEAR(out.standard_error[0], se, 1e-9 * se);
  EXPECT_NEAR(out.standard_error[1], 0.3, 1e-9);
  // Without the priors' pseudo-observation variance the first would be the data's alone,
  // sqrt(ss 6/5) / (6 + precision) -- smaller; the prior-held one would be 0.
  EXPECT_GT(se, std::sqrt(ss * 6 / 5) / (6 + precision) * 1.05);

  // As talus calibrate runs it: with the profiles measured beforehand, the second's flat (the
  // runs do not see it) -- it stays in the covariance, held by its prior, with the same numbers.
  const Eigen::Vector2d at((theta - 0.2) / 0.6, 0.5);
  options.profiles =
      ProfileParameters(objective, at, objective.Evaluate(at).value, 0.0, ProfileOptions{});
  ASSERT_EQ(options.profiles.size(), 2u);
  EXPECT_TRUE(options.profiles[0].identified);
  EXPECT_FALSE(options.profiles[1].identified);  // the data term does not change along it
  const Uncertainty pipeline = EstimateUncertainty(objective, at, options);
  ASSERT_TRUE(pipeline.computed) << pipeline.note;
  EXPECT_TRUE(pipeline.identified[1]);
  EXPECT_NEAR(pipeline.standard_error[0], se, 1e-9 * se);
  EXPECT_NEAR(pipeline.standard_error[1], 0.3, 1e-9);
}

// A fitted value more than 2 sds from its own prior's mean is a warning (the data and what the
// user stated disagree); within 2 sds, none. Summaries made by hand: no fit runs.
TEST(Prior, AFitFarFromItsPriorIsAWarning) {
  LinearProblem problem(6);
  const Objective objective = problem.Make(
      {WithPrior(Free(GroundField::kMuMin, 0.2, 0.8), {0.5, 0.1, 0})},
      [](const GroundValues& v, int g) { return v.mu_min - kY[g]; }, 0.1);
  CalibrationSummary run;
  run.fit.best.u = Eigen::VectorXd::Constant(1, (0.78 - 0.2) / 0.6);
  const std::vector<std::string> far = CalibrationWarnings(run, objective);
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].rfind("medium_hard.mu_min = 0.78 lies 2.8 sds from its prior normal(0.5, sd "
                         "0.1): the observations pull away from what was stated",
                         0),
            0u)
      << far[0];
  run.fit.best.u[0] = (0.68 - 0.2) / 0.6;
  EXPECT_TRUE(CalibrationWarnings(run, objective).empty());
}

}  // namespace
}  // namespace talus::calibration
