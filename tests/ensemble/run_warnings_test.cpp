// The warnings of a finished run: each rule of ensemble/run_warnings.hpp triggered by the endings
// that call for it, with the count, the share and the knob, and none for a clean run.

#include "ensemble/run_warnings.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace talus::ensemble {
namespace {

EnsembleReport Report(long rest, long left, long max_time, long failed, long stayed = 0) {
  EnsembleReport r;
  r.by_end = {rest, left, max_time, failed};
  r.rocks = rest + left + max_time + failed;
  r.stayed_at_release = stayed;
  return r;
}

bool Has(const std::vector<std::string>& warnings, const std::string& text) {
  for (const std::string& w : warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

TEST(RunWarnings, ACleanRunHasNone) {
  SolverOptions options;
  EXPECT_TRUE(RunWarnings(Report(200, 0, 0, 0), options).empty());
  EXPECT_TRUE(RunWarnings(Report(0, 0, 0, 0), options).empty());  // no rocks, nothing to say
}

TEST(RunWarnings, EveryRockAtMaxTimeIsCensoredAndSaysWhichKnob) {
  SolverOptions options;
  options.max_time_s = 120;
  const std::vector<std::string> w = RunWarnings(Report(168, 0, 32, 0), options);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Has(w, "32 of 200 rocks (16.0 %) were still moving at max_time_s = 120 s")) << w[0];
  EXPECT_TRUE(Has(w, "censored")) << w[0];
  EXPECT_TRUE(Has(w, "Raise [solver] max_time_s")) << w[0];
  // One rock is enough: any rock cut off biases the run-outs low.
  EXPECT_TRUE(Has(RunWarnings(Report(999, 0, 1, 0), options), "1 of 1000 rocks (0.1 %)"));
}

TEST(RunWarnings, RocksThatLeftTheDemAndFailedRocksAreNamed) {
  const std::vector<std::string> w = RunWarnings(Report(351, 889, 0, 0), SolverOptions{});
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Has(w, "889 of 1240 rocks (71.7 %) left the DEM")) << w[0];
  EXPECT_TRUE(Has(w, "lower bound")) << w[0];
  const std::vector<std::string> f = RunWarnings(Report(9, 0, 0, 1), SolverOptions{});
  ASSERT_EQ(f.size(), 1u);
  EXPECT_TRUE(Has(f, "1 of 10 rocks (10.0 %) failed")) << f[0];
}

TEST(RunWarnings, StayedAtReleaseAboveFivePercent) {
  // kStayedShare = 5 %: 5 of 100 are physics (blocks landing flat), 6 of 100 a warning.
  EXPECT_TRUE(RunWarnings(Report(100, 0, 0, 0, 5), SolverOptions{}).empty());
  const std::vector<std::string> w = RunWarnings(Report(100, 0, 0, 0, 6), SolverOptions{});
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(Has(w, "6 of 100 rocks (6.0 %) never got further than their own length")) << w[0];
}

TEST(RunWarnings, SeveralComeInAFixedOrder) {
  const std::vector<std::string> w = RunWarnings(Report(10, 3, 2, 1, 4), SolverOptions{});
  ASSERT_EQ(w.size(), 4u);
  EXPECT_NE(w[0].find("max_time"), std::string::npos);
  EXPECT_NE(w[1].find("left the DEM"), std::string::npos);
  EXPECT_NE(w[2].find("failed"), std::string::npos);
  EXPECT_NE(w[3].find("own length"), std::string::npos);
}

}  // namespace
}  // namespace talus::ensemble
