// The whole calibration through its one call, with no command line: the fit gives back the
// parameter that generated the observations, the held-out runs and the folds of a
// cross-validation are scored, the callbacks hear of every evaluation of every optimisation, and
// a run replayed from those evaluations (a checkpoint) ends where the first one did without
// running a rock in any optimisation.

#include "calibration/calibrate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

constexpr double kTruth = 0.5;  // medium_hard mu_min of the observations (Table 1: 0.40)
constexpr double kLower = 0.1, kUpper = 0.9;

const testing::SyntheticRunouts& Runouts() {
  static const testing::SyntheticRunouts problem(12, 4, kTruth);
  return problem;
}

// Ten runs fitted, two held out, the ten dealt into two folds; scored against the scene's table.
CalibrationProblem MakeProblem() {
  const auto& p = Runouts();
  ObjectiveOptions objective;
  objective.threads = 2;
  HeldOutChecks checks;
  checks.holdout = {"run3", "run8"};
  checks.folds = 2;
  checks.reference = p.scene.ground;
  return CalibrationProblem(p.scene, p.release, p.observations,
                            {testing::Spec("medium_hard", GroundField::kMuMin, kLower, kUpper)},
                            objective, checks);
}

// BOBYQA from mu_min 0.2, nothing measured at the optimum (this tests the pipeline, not them).
CalibrationOptions FitOnly() {
  CalibrationOptions options;
  options.optimizer.algorithm = "bobyqa";
  options.optimizer.max_evaluations = 12;
  options.optimizer.initial_step = 0.2;
  options.optimizer.start = Eigen::VectorXd::Constant(1, (0.2 - kLower) / (kUpper - kLower));
  options.roughness = false;
  options.uncertainty = false;
  return options;
}

// Each optimisation's evaluations as the callbacks heard them, and the text for people.
struct Heard {
  std::map<std::string, std::vector<Evaluation>> evaluations;
  std::vector<std::string> begun, ended;
  std::string text;
};

CalibrationOptions Listening(CalibrationOptions options, Heard& heard) {
  options.on_optimization_begins = [&heard](const std::string& stage) {
    heard.begun.push_back(stage);
  };
  options.on_evaluation = [&heard](const std::string& stage, const Evaluation& e, int index) {
    EXPECT_EQ(index, static_cast<int>(heard.evaluations[stage].size())) << stage;
    heard.evaluations[stage].push_back(e);
  };
  options.on_optimization_ends = [&heard](const std::string& stage) {
    heard.ended.push_back(stage);
  };
  options.on_progress = [&heard](const std::string& text) { heard.text += text; };
  return options;
}

// The fitted mu_min lies within 3 of the data's standard errors (testing::MeasuredDataError,
// for the ten fitted runs) plus the optimiser's tolerance of the truth; the start does not.
TEST(Calibrate, TheOneCallRecoversMuMinAndScoresHeldOutRunsAndFolds) {
  const CalibrationProblem problem = MakeProblem();
  ASSERT_EQ(problem.fitted_runs().release.runs.size(), 10u);
  ASSERT_EQ(problem.folds().size(), 2u);
  Heard heard;
  const CalibrationSummary run = Calibrate(problem, Listening(FitOnly(), heard));
  std::printf("%s\n%s\n", run.FullReport().c_str(), run.BriefReport().c_str());
  ASSERT_TRUE(run.fit.IsSolutionUsable());

  const auto& p = Runouts();
  const testing::DataError data = testing::MeasuredDataError(
      p.scene, p.release, p.observations, testing::SetMediumHardMuMin, kTruth, 0.05);
  const double se = data.se * std::sqrt(double(p.observations.scalars.size()) / 10.0);
  const double tolerance = 3 * se + FitOnly().optimizer.xtol_abs * (kUpper - kLower);
  const double fitted = run.fit.best.values[0];
  std::printf("fitted mu_min %.4f (truth %.2f); standard error %.4f, tolerance %.4f\n", fitted,
              kTruth, se, tolerance);
  EXPECT_NEAR(fitted, kTruth, tolerance);
  EXPECT_GT(std::abs(0.2 - kTruth), tolerance);
  const GroundTable& table = run.fitted;
  EXPECT_EQ(table.params(table.IndexOfName("medium_hard")).mu_min, fitted);

  // Held out: the two runs, with the fitted and the reference table. Cross-validated: every
  // fitted run once, by the fit without its fold.
  ASSERT_TRUE(run.holdout.has_value());
  EXPECT_EQ(run.holdout->runs, (std::vector<std::string>{"run3", "run8"}));
  ASSERT_EQ(run.holdout->kinds.size(), 1u);
  EXPECT_EQ(run.holdout->kinds[0].scored, 2);
  EXPECT_TRUE(std::isfinite(run.holdout->kinds[0].fitted));
  EXPECT_TRUE(std::isfinite(run.holdout->kinds[0].reference));
  ASSERT_EQ(run.folds.size(), 2u);
  ASSERT_EQ(run.cross_validated.size(), 1u);
  EXPECT_EQ(run.cross_validated[0].observations, 10);
  EXPECT_EQ(run.before.observations.size(), 10u);
  EXPECT_EQ(run.after.observations.size(), 10u);

  // The callbacks heard every evaluation of the fit and of each fold, in order.
  EXPECT_EQ(heard.begun, (std::vector<std::string>{"fit", "fold1", "fold2"}));
  EXPECT_EQ(heard.ended, heard.begun);
  EXPECT_EQ(heard.evaluations["fit"].size(), run.fit.history.size());
  EXPECT_EQ(heard.evaluations["fold1"].size(), run.folds[0].summary.history.size());
  EXPECT_EQ(heard.evaluations["fold2"].size(), run.folds[1].summary.history.size());
  EXPECT_NE(heard.text.find(run.fit.FullReport()), std::string::npos);
  EXPECT_NE(heard.text.find("Cross-validated (2 folds)"), std::string::npos) << heard.text;

  // Replayed from what the callbacks heard (a checkpoint), every optimisation retraces its path
  // without running a rock and the run ends where this one did.
  CalibrationOptions replay = FitOnly();
  replay.replay = heard.evaluations;
  const CalibrationSummary again = Calibrate(problem, replay);
  EXPECT_EQ(again.fit.replayed, again.fit.evaluations());
  EXPECT_EQ(again.fit.best.u, run.fit.best.u);
  EXPECT_EQ(again.fit.best.value, run.fit.best.value);
  for (std::size_t f = 0; f < run.folds.size(); ++f) {
    EXPECT_EQ(again.folds[f].summary.replayed, again.folds[f].summary.evaluations()) << f;
    EXPECT_EQ(again.folds[f].summary.best.u, run.folds[f].summary.best.u) << f;
  }
  EXPECT_EQ(again.holdout->kinds[0].fitted, run.holdout->kinds[0].fitted);
  EXPECT_EQ(again.cross_validated[0].fitted, run.cross_validated[0].fitted);
}

// Bad splits are refused when the problem is built, before any rock runs.
TEST(CalibrationProblem, RefusesAnUnknownHeldOutRunAndTooManyFolds) {
  const auto& p = Runouts();
  const std::vector<ParameterSpec> parameters = {
      testing::Spec("medium_hard", GroundField::kMuMin, kLower, kUpper)};
  HeldOutChecks unknown;
  unknown.holdout = {"run99"};
  EXPECT_THROW(CalibrationProblem(p.scene, p.release, p.observations, parameters, {}, unknown),
               InputError);
  HeldOutChecks folds;
  folds.folds = 13;  // 12 runs
  EXPECT_THROW(CalibrationProblem(p.scene, p.release, p.observations, parameters, {}, folds),
               InputError);
}

}  // namespace
}  // namespace talus::calibration
