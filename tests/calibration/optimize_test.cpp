// Optimize (calibration/optimize.hpp), the one call of the calibration's optimiser: invalid
// options are refused before anything runs, with the option named; "ceres" goes to the
// least-squares back-end and every other name to NLopt; both reach the closed-form minimiser of a
// linear least-squares problem (no rock runs: linear_problem.hpp).

#include "calibration/optimize.hpp"

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

// r_g = mu_min - y_g: minimised at the mean of y, 0.47.
Objective MeanProblem(const LinearProblem& problem) {
  static const double y[4] = {0.40, 0.45, 0.50, 0.53};
  return problem.Make({Free(GroundField::kMuMin, 0.2, 0.8)},
                      [](const GroundValues& v, int g) { return v.mu_min - y[g]; });
}

TEST(Optimize, InvalidOptionsAreRefusedBeforeAnyEvaluation) {
  LinearProblem problem(4);
  const Objective objective = MeanProblem(problem);
  const auto message = [&](OptimizerOptions o) {
    try {
      Optimize(objective, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  OptimizerOptions o;
  o.algorithm = "nelder_mead";
  EXPECT_EQ(message(o),
            "Optimize: algorithm = 'nelder_mead' is not one of bobyqa, sbplx, crs2_lm, direct_l, "
            "isres, ceres");
  o = {};
  o.max_evaluations = 0;
  EXPECT_EQ(message(o), "Optimize: max_evaluations = 0 must be >= 1");
  o = {};
  o.algorithm = "ceres";
  o.fd_step = 0.5;
  EXPECT_EQ(message(o), "Optimize: fd_step = 0.5 must be in [0, 0.25] (0: measured)");
  o = {};
  o.starts = 3;
  o.max_evaluations = 2;
  EXPECT_EQ(message(o), "Optimize: starts = 3 must be in 1 .. max_evaluations = 2");
  EXPECT_EQ(*problem.runs, 0) << "nothing may run with invalid options";
}

// The back-end by name: Ceres records its central-difference step (here the one given), NLopt
// leaves it NaN; both find the mean 0.47 (u = 0.45).
TEST(Optimize, DispatchesByAlgorithmNameAndBothBackEndsFindTheMinimiser) {
  LinearProblem problem(4);
  const Objective objective = MeanProblem(problem);
  for (const char* name : {"ceres", "bobyqa", "sbplx"}) {
    OptimizerOptions options;
    options.algorithm = name;
    options.fd_step = 0.02;
    options.xtol_abs = 1e-7;
    options.ftol_rel = 1e-12;
    const OptimizerSummary summary = Optimize(objective, options);
    EXPECT_EQ(summary.algorithm, name);
    ASSERT_TRUE(summary.IsSolutionUsable()) << name;
    EXPECT_NEAR(summary.best.values[0], 0.47, 1e-5) << name;
    EXPECT_EQ(summary.termination, Termination::kConvergence) << name << ": " << summary.message;
    if (std::string(name) == "ceres") {
      EXPECT_EQ(summary.fd_step, 0.02);
    } else {
      EXPECT_TRUE(std::isnan(summary.fd_step)) << name;
    }
  }
}

}  // namespace
}  // namespace talus::calibration
