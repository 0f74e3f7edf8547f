// Held-out runs and folds: drawn deterministically from the seed, disjoint, covering every run;
// a subset keeps exactly its runs' observations; unknown runs and impossible splits are refused;
// pooled scores are the means over every held-out observation.

#include "calibration/holdout.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "common/error.hpp"

namespace talus::calibration {
namespace {

ensemble::ReleaseSpec Runs(int n) {
  ensemble::ReleaseSpec release;
  for (int r = 0; r < n; ++r) {
    ensemble::ReleaseRun run;
    run.id = "r";
    run.id += std::to_string(r);  // (GCC 12 warns wrongly about "r" + std::string)
    release.runs.push_back(run);
  }
  return release;
}

TEST(Holdout, PickedRunsAreDeterministicDistinctAndInReleaseOrder) {
  const ensemble::ReleaseSpec release = Runs(10);
  const std::vector<std::string> a = PickRuns(release, 3, 7), b = PickRuns(release, 3, 7);
  EXPECT_EQ(a, b);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(std::set<std::string>(a.begin(), a.end()).size(), 3u);
  std::vector<std::string> order = OtherRuns(release, OtherRuns(release, a));
  EXPECT_EQ(order, a);                    // release order
  EXPECT_NE(PickRuns(release, 3, 8), a);  // another seed, other runs (for these seeds)
  EXPECT_THROW(PickRuns(release, 10, 7), InputError);
  EXPECT_THROW(PickRuns(release, 0, 7), InputError);
}

TEST(Holdout, FoldsAreDisjointCoverEveryRunAndDifferInSizeByAtMostOne) {
  const ensemble::ReleaseSpec release = Runs(11);
  const auto folds = Folds(release, 3, 1);
  ASSERT_EQ(folds.size(), 3u);
  std::multiset<std::string> all;
  std::size_t smallest = 11, largest = 0;
  for (const auto& fold : folds) {
    all.insert(fold.begin(), fold.end());
    smallest = std::min(smallest, fold.size());
    largest = std::max(largest, fold.size());
  }
  EXPECT_EQ(all.size(), 11u);
  EXPECT_EQ(std::set<std::string>(all.begin(), all.end()).size(), 11u);
  EXPECT_LE(largest - smallest, 1u);
  EXPECT_EQ(Folds(release, 3, 1), folds);
  EXPECT_THROW(Folds(release, 1, 1), InputError);
  EXPECT_THROW(Folds(release, 12, 1), InputError);
}

TEST(Holdout, ASubsetKeepsItsRunsAndTheirObservations) {
  const ensemble::ReleaseSpec release = Runs(4);
  fieldobs::ObservationSet observations;
  for (const char* run : {"r0", "r1", "r2", "r3", ""})
    observations.scalars.push_back({fieldobs::Quantity::kRunout, run, 10, "t.csv:1"});
  observations.deposits.push_back({"r2", Eigen::Vector2d(1, 2), std::nullopt, "t.csv:2"});
  const RunSubset held = SelectRuns(release, observations, {"r2", "r0"}, false);
  ASSERT_EQ(held.release.runs.size(), 2u);
  EXPECT_EQ(held.release.runs[0].id, "r0");  // release order
  EXPECT_EQ(held.release.runs[1].id, "r2");
  EXPECT_EQ(held.observations.scalars.size(), 2u);
  EXPECT_EQ(held.observations.deposits.size(), 1u);
  const RunSubset fit = SelectRuns(release, observations, OtherRuns(release, {"r2", "r0"}), true);
  EXPECT_EQ(fit.observations.scalars.size(), 3u);  // r1, r3 and the scene's
  EXPECT_EQ(fit.observations.deposits.size(), 0u);
  EXPECT_THROW(SelectRuns(release, observations, {"r9"}, false), InputError);
}

TEST(Holdout, PooledScoresAreMeansOverEveryHeldOutObservation) {
  const auto score = [](const char* kind, double fitted, double reference) {
    fieldobs::ObservationScore s;
    s.kind = kind;
    s.unit = "m";
    s.scored = true;
    s.score = fitted;
    s.reference_score = reference;
    return s;
  };
  HeldOutScores a, b;
  a.observations = {score("runout", 1, 2), score("runout", 3, 4)};
  b.observations = {score("runout", 5, 6), score("deposit", 7, 8)};
  const std::vector<HeldOutKind> kinds = PoolKinds({a, b});
  ASSERT_EQ(kinds.size(), 2u);
  EXPECT_EQ(kinds[0].kind, "runout");
  EXPECT_EQ(kinds[0].scored, 3);
  EXPECT_DOUBLE_EQ(kinds[0].fitted, 3.0);
  EXPECT_DOUBLE_EQ(kinds[0].reference, 4.0);
  EXPECT_EQ(kinds[1].kind, "deposit");
  EXPECT_DOUBLE_EQ(kinds[1].fitted, 7.0);
}

}  // namespace
}  // namespace talus::calibration
