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

// Each warning of a result, from a summary made by hand (no rock runs): mu_min at its lower
// bound with a flat profile, a profile point 0.5 below the optimum (noise 0.1), and held-out
// run-outs and cross-validated rest positions scoring worse fitted than with the reference; a
// profile point below the optimum by less than the noise, and kinds scoring better fitted, give
// none.
TEST(CalibrationWarnings, EachWeakOrCensoredResultIsSaid) {
  const CalibrationProblem problem = MakeProblem();
  CalibrationSummary run;
  run.fit.best.u = Eigen::VectorXd::Constant(1, 0.0);
  run.fit.best.value = 1.0;
  ParameterProfile profile;
  profile.name = "medium_hard.mu_min";
  profile.u = {0, 0.5, 1};
  profile.values = {kLower, 0.5, kUpper};
  profile.f = {1.0, 0.5, 1.2};
  profile.range = 0.7;
  profile.threshold = 0.9;
  profile.identified = false;
  run.profiles = {profile};
  run.roughness = RoughnessReport{};
  run.roughness->noise = 0.1;
  run.holdout = HeldOutScores{};
  run.holdout->kinds = {{"runout", "m", 2, 2, 12.0, 10.0}, {"deposit", "m", 2, 2, 9.0, 10.0}};
  run.cross_validated = {{"runout", "m", 6, 6, 9.0, 10.0}, {"deposit", "m", 6, 6, 14.0, 13.0}};
  const std::vector<std::string> w = CalibrationWarnings(run, problem.objective());
  ASSERT_EQ(w.size(), 5u);
  EXPECT_EQ(w[0].rfind("medium_hard.mu_min is unidentified: over its whole range its profile "
                       "changes the objective's data term by 0.7, not more than 0.9",
                       0),
            0u)
      << w[0];
  EXPECT_EQ(w[1].rfind("medium_hard.mu_min lies at the lower bound of its range (0.1)", 0), 0u)
      << w[1];
  EXPECT_EQ(w[2].rfind("the profile of medium_hard.mu_min found a lower objective (0.5 at 0.5) "
                       "than the reported optimum (1)",
                       0),
            0u)
      << w[2];
  EXPECT_EQ(w[3].rfind("the held-out runs score runout worse with the fitted values than with "
                       "the reference table (12 against 10 m)",
                       0),
            0u)
      << w[3];
  EXPECT_EQ(w[4].rfind("the cross-validated runs score deposit worse", 0), 0u) << w[4];

  // The rocks-per-run rule: its number, or none where it is beyond any calibration's means.
  run.profiles[0].rocks_to_identify = 46.2;
  EXPECT_NE(CalibrationWarnings(run, problem.objective())[0].find(
                "; about 47 rocks per run would (the noise falls as 1/sqrt(rocks))"),
            std::string::npos);
  run.profiles[0].rocks_to_identify = 2e7;
  EXPECT_NE(CalibrationWarnings(run, problem.objective())[0].find(
                "; no practical number of rocks per run would (its range is 0.78 of its "
                "threshold)"),
            std::string::npos);

  // Within the noise, inside the bounds, identified, better fitted: nothing to say.
  run.fit.best.u[0] = 0.5;
  run.profiles[0].identified = true;
  run.profiles[0].f = {1.2, 0.95, 1.1};
  run.holdout->kinds[0].fitted = 9.0;
  run.cross_validated[1].fitted = 12.0;
  EXPECT_TRUE(CalibrationWarnings(run, problem.objective()).empty());
}

}  // namespace
}  // namespace talus::calibration
