// The optimisers' shared bookkeeping: the history and its cache, the best feasible evaluation,
// serving a checkpoint's evaluations, the budgets and how a run's termination is stated.

#include "calibration/evaluator.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

const testing::SyntheticRunouts& Problem() {
  static const testing::SyntheticRunouts problem(3, 3, 0.5);
  return problem;
}

const Objective& MuMinObjective() {
  static const Objective objective(Problem().scene, Problem().release, Problem().observations,
                                   {testing::Spec("medium_hard", GroundField::kMuMin, 0.1, 0.9)},
                                   ObjectiveOptions{});
  return objective;
}

Eigen::VectorXd U(double u) { return Eigen::VectorXd::Constant(1, u); }

// A recorded evaluation at u with the given value (as a checkpoint holds it).
Evaluation Recorded(double u, double value, bool feasible = true) {
  Evaluation e;
  e.u = U(u);
  e.values = U(0.1 + 0.8 * u);
  e.value = value;
  e.feasible = feasible;
  if (!feasible) e.infeasible = "made up";
  return e;
}

TEST(Evaluator, RunsTheObjectiveAndAnswersAPointAskedAgainFromTheHistory) {
  OptimizerOptions options;
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  const Evaluation a = evaluate(U(0.3));
  EXPECT_EQ(a.value, MuMinObjective().Evaluate(U(0.3)).value);  // what the objective says
  evaluate.set_start(1);
  const Evaluation b = evaluate(U(0.6));
  const Evaluation again = evaluate(U(0.3));
  EXPECT_EQ(again.value, a.value);
  EXPECT_EQ(summary.evaluations(), 2);
  EXPECT_EQ(summary.cache_hits, 1);
  EXPECT_EQ(summary.history_start, (std::vector<int>{0, 1}));
  EXPECT_EQ(summary.initial.u, U(0.3));
  EXPECT_EQ(summary.best.value, std::min(a.value, b.value));
}

TEST(Evaluator, ServesACheckpointInOrderWithoutRunningRocksAndKeepsTheBestFeasible) {
  OptimizerOptions options;
  options.replay = {Recorded(0.5, 3.0), Recorded(0.7, 1.0, false), Recorded(0.2, 2.0)};
  std::vector<int> seen;
  options.on_evaluation = [&](const Evaluation&, int index) { seen.push_back(index); };
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  EXPECT_EQ(evaluate(U(0.5)).value, 3.0);  // the recorded value, not a run's
  EXPECT_EQ(summary.best.value, 3.0);
  EXPECT_EQ(evaluate(U(0.7)).value, 1.0);
  EXPECT_EQ(summary.best.value, 3.0);  // the lower value is infeasible
  EXPECT_EQ(evaluate(U(0.2)).value, 2.0);
  EXPECT_EQ(summary.best.value, 2.0);
  EXPECT_EQ(summary.replayed, 3);
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 2}));
  // Past the checkpoint's end, the objective runs.
  EXPECT_EQ(evaluate(U(0.4)).value, MuMinObjective().Evaluate(U(0.4)).value);
  EXPECT_EQ(summary.replayed, 3);
  EXPECT_EQ(summary.evaluations(), 4);
}

TEST(Evaluator, ACheckpointOfAnotherCalibrationIsRefused) {
  OptimizerOptions options;
  options.replay = {Recorded(0.5, 3.0), Recorded(0.7, 1.0)};
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  evaluate(U(0.5));
  try {
    evaluate(U(0.6));
    ADD_FAILURE() << "a point the checkpoint did not record was served";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("checkpoint: evaluation 1"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(summary.evaluations(), 1);
}

// A replayed evaluation whose u has another number of coordinates (a damaged checkpoint) is the
// same refusal, not a comparison of vectors of different sizes (which crashed).
TEST(Evaluator, ACheckpointEvaluationOfAnotherDimensionIsRefused) {
  for (const Eigen::VectorXd& u :
       {Eigen::VectorXd(), Eigen::VectorXd(Eigen::VectorXd::Constant(3, 0.5))}) {
    OptimizerOptions options;
    Evaluation recorded = Recorded(0.5, 3.0);
    recorded.u = u;
    options.replay = {recorded};
    OptimizerSummary summary;
    Evaluator evaluate(MuMinObjective(), options, summary);
    EXPECT_THROW(evaluate(U(0.5)), std::runtime_error) << u.size();
    EXPECT_EQ(summary.evaluations(), 0);
  }
}

TEST(Evaluator, StopsAtTheEvaluationBudgetButStillAnswersKnownPoints) {
  OptimizerOptions options;
  options.max_evaluations = 2;
  options.replay = {Recorded(0.1, 5.0), Recorded(0.2, 4.0)};
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  EXPECT_TRUE(evaluate.TryEvaluate(U(0.1)));
  EXPECT_FALSE(evaluate.out_of_evaluations());
  EXPECT_TRUE(evaluate.TryEvaluate(U(0.2)));
  EXPECT_TRUE(evaluate.out_of_evaluations());
  EXPECT_TRUE(evaluate.stopped());
  EXPECT_FALSE(evaluate.TryEvaluate(U(0.3)));  // no new evaluation
  const std::optional<Evaluation> known = evaluate.TryEvaluate(U(0.1));
  ASSERT_TRUE(known);
  EXPECT_EQ(known->value, 5.0);
  EXPECT_EQ(summary.evaluations(), 2);
  evaluate.Finish(true, false, "", "");
  EXPECT_EQ(summary.termination, Termination::kMaxEvaluations);
  EXPECT_EQ(summary.message, "evaluation budget of 2 spent");
}

TEST(Evaluator, StopsAtTheTimeBudgetWhichOutranksTheOtherEndings) {
  OptimizerOptions options;
  options.max_time_s = 0.01;
  options.replay = {Recorded(0.1, 5.0)};
  options.on_evaluation = [](const Evaluation&, int) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  };
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  EXPECT_TRUE(evaluate.TryEvaluate(U(0.1)));
  EXPECT_TRUE(evaluate.out_of_time());
  EXPECT_FALSE(evaluate.TryEvaluate(U(0.5)));
  evaluate.Finish(true, true, "xtol", "");
  EXPECT_EQ(summary.termination, Termination::kMaxTime);
  EXPECT_EQ(summary.message, "wall-time budget of 0.01 s spent");
  EXPECT_GE(summary.wall_time_s, 0.02);
}

TEST(Evaluator, AnExceptionFromACallbackIsKeptForRethrowAndStopsTheRun) {
  OptimizerOptions options;
  options.replay = {Recorded(0.1, 5.0), Recorded(0.2, 4.0)};
  options.on_evaluation = [](const Evaluation&, int index) {
    if (index == 1) throw std::runtime_error("interrupted");
  };
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  EXPECT_TRUE(evaluate.TryEvaluate(U(0.1)));
  EXPECT_FALSE(evaluate.TryEvaluate(U(0.2)));
  EXPECT_TRUE(evaluate.stopped());
  EXPECT_FALSE(evaluate.TryEvaluate(U(0.3)));
  EXPECT_THROW(evaluate.Rethrow(), std::runtime_error);
}

TEST(Evaluator, FinishStatesConvergenceOrFailureAndAMissingFeasibleEvaluation) {
  OptimizerOptions options;
  options.replay = {Recorded(0.1, 5.0)};
  OptimizerSummary summary;
  Evaluator evaluate(MuMinObjective(), options, summary);
  evaluate(U(0.1));
  evaluate.Finish(false, true, "ftol_rel", "roundoff");
  EXPECT_EQ(summary.termination, Termination::kConvergence);
  EXPECT_EQ(summary.message, "converged (ftol_rel)");
  evaluate.Finish(false, false, "ftol_rel", "NLopt: roundoff-limited");
  EXPECT_EQ(summary.termination, Termination::kFailure);
  EXPECT_EQ(summary.message, "NLopt: roundoff-limited");

  OptimizerOptions infeasible;
  infeasible.replay = {Recorded(0.1, 5.0, false)};
  OptimizerSummary none;
  Evaluator only_infeasible(MuMinObjective(), infeasible, none);
  only_infeasible(U(0.1));
  only_infeasible.Finish(false, true, "xtol_abs", "");
  EXPECT_FALSE(none.IsSolutionUsable());
  EXPECT_EQ(none.message, "converged (xtol_abs); no feasible evaluation");
}

}  // namespace
}  // namespace talus::calibration
