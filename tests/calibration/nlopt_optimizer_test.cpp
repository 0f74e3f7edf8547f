// The NLopt back-end (calibration/nlopt_optimizer.hpp) on objectives with a closed-form minimiser
// and no rock runs (linear_problem.hpp): every algorithm by name reaches it, the evaluation budget
// is kept across starts, the stochastic methods are reproducible from their seed, and a minimiser
// outside the box ends on the bound.

#include "calibration/nlopt_optimizer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "linear_problem.hpp"

namespace talus::calibration {
namespace {

using testing::Free;
using testing::GroundValues;
using testing::LinearProblem;

// f(u) = sum_g r_g^2 with r_g = (mu_min - 0.5) + (g - 2) (mu_max - 2.2) / 4 over 5 runs: the
// unique minimiser mu_min = 0.5, mu_max = 2.2 (u = (0.5, 0.6)) with f = 0.
Objective Bowl(const LinearProblem& problem) {
  return problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8), Free(GroundField::kMuMax, 1.0, 3.0)},
      [](const GroundValues& v, int g) {
        return (v.mu_min - 0.5) + (g - 2) * (v.mu_max - 2.2) / 4;
      });
}

// Local methods to their x tolerance (1e-4 in unit coordinates, checked at 1e-3); global methods
// within their budget of 600 evaluations to 0.05 (they sample the box, not the bowl's bottom).
TEST(OptimizeNlopt, EveryAlgorithmReachesTheMinimiser) {
  LinearProblem problem(5);
  const Objective objective = Bowl(problem);
  for (const char* name : {"bobyqa", "sbplx", "crs2_lm", "direct_l", "isres"}) {
    OptimizerOptions options;
    options.algorithm = name;
    options.max_evaluations = 600;
    options.xtol_abs = 1e-4;
    options.ftol_rel = 0;
    options.ftol_abs = 1e-12;
    const OptimizerSummary summary = OptimizeNlopt(objective, options);
    EXPECT_EQ(summary.algorithm, name);
    ASSERT_TRUE(summary.IsSolutionUsable()) << name;
    const double tolerance = IsLocalAlgorithm(name) ? 1e-3 : 0.05;
    EXPECT_NEAR(summary.best.u[0], 0.5, tolerance) << name;
    EXPECT_NEAR(summary.best.u[1], 0.6, tolerance) << name;
    EXPECT_LE(summary.evaluations(), 600) << name;
    EXPECT_EQ(summary.names,
              (std::vector<std::string>{"medium_hard.mu_min", "medium_hard.mu_max"}));
    EXPECT_TRUE(std::isnan(summary.fd_step)) << "a Ceres-only field";
    // The first evaluation is the start point: the scene's table (Table 1's medium_hard).
    const GroundParams& table =
        problem.scene.ground.params(problem.scene.ground.IndexOfName("medium_hard"));
    EXPECT_EQ(summary.history.front().values[0], table.mu_min) << name;
    EXPECT_EQ(summary.history.front().values[1], table.mu_max) << name;
  }
}

// Several starts share the budget: no more evaluations than allowed in all, each start recorded
// with its own evaluations (summing to the history, less the first evaluation that the first start
// reuses) and history_start labelling every evaluation; a spent budget is the termination.
TEST(OptimizeNlopt, StartsShareTheEvaluationBudget) {
  LinearProblem problem(5);
  const Objective objective = Bowl(problem);
  OptimizerOptions options;
  options.algorithm = "sbplx";
  options.max_evaluations = 40;
  options.starts = 4;
  options.xtol_abs = 1e-12;
  options.ftol_rel = 0;
  const OptimizerSummary summary = OptimizeNlopt(objective, options);
  EXPECT_LE(summary.evaluations(), 40);
  EXPECT_EQ(summary.termination, Termination::kMaxEvaluations) << summary.message;
  ASSERT_EQ(summary.starts.size(), 4u);
  ASSERT_EQ(summary.history_start.size(), summary.history.size());
  int total = 0;
  for (std::size_t s = 0; s < summary.starts.size(); ++s) {
    total += summary.starts[s].evaluations;
    EXPECT_GT(summary.starts[s].evaluations, 0) << s;
    EXPECT_EQ(std::count(summary.history_start.begin(), summary.history_start.end(),
                         static_cast<int>(s)),
              summary.starts[s].evaluations + (s == 0 ? 1 : 0))
        << s;
  }
  EXPECT_EQ(total + 1, summary.evaluations());
  EXPECT_EQ(*problem.runs, summary.evaluations());  // each evaluation ran its rocks once
}

// CRS2-LM and ISRES draw from NLopt's generator, seeded from options.seed (plus the start): the
// same seed gives the same path, another seed another one.
TEST(OptimizeNlopt, StochasticMethodsAreReproducibleFromTheSeed) {
  LinearProblem problem(5);
  const Objective objective = Bowl(problem);
  for (const char* name : {"crs2_lm", "isres"}) {
    OptimizerOptions options;
    options.algorithm = name;
    options.max_evaluations = 60;
    options.seed = 7;
    const OptimizerSummary a = OptimizeNlopt(objective, options);
    const OptimizerSummary b = OptimizeNlopt(objective, options);
    options.seed = 8;
    const OptimizerSummary c = OptimizeNlopt(objective, options);
    ASSERT_EQ(a.evaluations(), b.evaluations()) << name;
    bool differs = a.evaluations() != c.evaluations();
    for (int k = 0; k < a.evaluations(); ++k) {
      EXPECT_EQ(a.history[k].u, b.history[k].u) << name << " evaluation " << k;
      if (!differs && k < c.evaluations() && a.history[k].u != c.history[k].u) differs = true;
    }
    EXPECT_TRUE(differs) << name << ": seeds 7 and 8 gave the same path";
  }
}

// A minimiser beyond the box (mu_min = 1.0 > 0.8): the fit is on the bound, u = 1.
TEST(OptimizeNlopt, MinimiserOutsideTheBoxEndsOnTheBound) {
  LinearProblem problem(3);
  const Objective objective = problem.Make(
      {Free(GroundField::kMuMin, 0.2, 0.8)},
      [](const GroundValues& v, int g) { return (v.mu_min - 1.0) * (g + 1); });
  OptimizerOptions options;
  options.algorithm = "bobyqa";
  options.xtol_abs = 1e-6;
  const OptimizerSummary summary = OptimizeNlopt(objective, options);
  ASSERT_TRUE(summary.IsSolutionUsable());
  EXPECT_NEAR(summary.best.u[0], 1.0, 1e-6);
  EXPECT_NEAR(summary.best.values[0], 0.8, 1e-6);
  EXPECT_NEAR(summary.best.value, 0.04 * (1 + 4 + 9), 1e-5);
}

}  // namespace
}  // namespace talus::calibration
