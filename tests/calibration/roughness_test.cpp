// The roughness measurement and the parameter profiles: what each number of the report is made
// of, checked against direct evaluations of a small objective.

#include "calibration/roughness.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

const testing::SyntheticRunouts& Problem() {
  static const testing::SyntheticRunouts problem(3, 3, 0.5);
  return problem;
}

// mu_min (identified by run-outs) and beta (scar decay in flight: these rocks barely fly).
const Objective& TwoParameterObjective() {
  static const Objective objective(Problem().scene, Problem().release, Problem().observations,
                                   {testing::Spec("medium_hard", GroundField::kMuMin, 0.1, 0.9),
                                    testing::Spec("medium_hard", GroundField::kBeta, 100, 200)},
                                   ObjectiveOptions{});
  return objective;
}

TEST(RoughnessOptions, DefaultsAreValidAndBadValuesNamed) {
  std::string why;
  EXPECT_TRUE(RoughnessOptions().IsValid(&why)) << why;
  RoughnessOptions o;
  o.steps = {};
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("at least one step"), std::string::npos) << why;
  o.steps = {1e-3, 0.6};
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("steps: 0.6"), std::string::npos) << why;
  o = RoughnessOptions();
  o.seeds = -1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("seeds = -1"), std::string::npos) << why;
  o = RoughnessOptions();
  o.signal_to_noise = 0.5;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("signal_to_noise = 0.5"), std::string::npos) << why;
}

TEST(MeasureRoughness, EveryNumberIsTheStatedFunctionOfDirectEvaluations) {
  const Objective& objective = TwoParameterObjective();
  const Eigen::Vector2d u(0.5, 1.0);  // beta at its upper bound: its steps go inwards
  RoughnessOptions options;
  options.steps = {1e-1, 1e-3};  // unsorted on purpose
  options.seeds = 2;
  const RoughnessReport r = MeasureRoughness(objective, u, options);

  EXPECT_EQ(r.steps, (std::vector<double>{1e-3, 1e-1}));
  EXPECT_EQ(r.evaluations, 1 + 2 * 2 + 2);
  const double f = objective.Evaluate(u).value;
  EXPECT_EQ(r.value, f);
  ASSERT_EQ(r.change.size(), 2u);
  for (std::size_t s = 0; s < 2; ++s) {
    const double h = r.steps[s];
    ASSERT_EQ(r.change[s].size(), 2u);
    EXPECT_EQ(r.change[s][0], std::abs(objective.Evaluate(Eigen::Vector2d(0.5 + h, 1)).value - f));
    EXPECT_EQ(r.change[s][1], std::abs(objective.Evaluate(Eigen::Vector2d(0.5, 1 - h)).value - f));
  }
  EXPECT_EQ(r.noise, std::max(r.change[0][0], r.change[0][1]));
  EXPECT_EQ(r.ftol_abs, 2 * r.noise);

  // Other seeds: other rocks, and the standard deviation of all three values.
  ASSERT_EQ(r.seed_values.size(), 2u);
  const std::uint64_t seed = objective.release().seed;
  EXPECT_EQ(r.seed_values[0], objective.EvaluateWithSeed(u, seed + 1).value);
  EXPECT_EQ(r.seed_values[1], objective.EvaluateWithSeed(u, seed + 2).value);
  const double mean = (f + r.seed_values[0] + r.seed_values[1]) / 3;
  const double sd = std::sqrt((std::pow(f - mean, 2) + std::pow(r.seed_values[0] - mean, 2) +
                               std::pow(r.seed_values[1] - mean, 2)) /
                              2);
  EXPECT_NEAR(r.seed_sd, sd, 1e-12 * std::max(1.0, sd));
  EXPECT_EQ(r.level(), std::max(r.noise, r.seed_sd));

  // The finite-difference step: the smallest step whose median change clears signal_to_noise x
  // the noise, else the largest. With two coordinates the median at the smallest step is the
  // noise itself, which never clears 10 x itself: the larger step, picked or by default.
  EXPECT_EQ(r.fd_step, r.steps[1]);
  const std::string report = r.Report();
  EXPECT_NE(report.find("7 evaluations"), std::string::npos) << report;
  EXPECT_NE(report.find("sd over 2 other seeds"), std::string::npos) << report;
}

TEST(MeasureRoughness, WithoutOtherSeedsTheLevelIsTheRoughness) {
  RoughnessOptions options;
  options.steps = {1e-2};
  options.seeds = 0;
  const RoughnessReport r =
      MeasureRoughness(TwoParameterObjective(), Eigen::Vector2d(0.3, 0.3), options);
  EXPECT_EQ(r.evaluations, 3);
  EXPECT_TRUE(r.seed_values.empty());
  EXPECT_TRUE(std::isnan(r.seed_sd));
  EXPECT_EQ(r.level(), r.noise);
  EXPECT_EQ(r.fd_step, 1e-2);
}

TEST(ProfileParameters, WalksEachCoordinateAcrossItsRangeAndJudgesItsRangeAgainstTheNoise) {
  const Objective& objective = TwoParameterObjective();
  const Eigen::Vector2d u(0.5, 0.5);
  const double f = objective.Evaluate(u).value;
  ProfileOptions options;
  options.points = 3;
  options.noise_multiple = 3;
  const double noise = 1e-3;
  const std::vector<ParameterProfile> profiles = ProfileParameters(objective, u, f, noise, options);
  ASSERT_EQ(profiles.size(), 2u);
  EXPECT_EQ(profiles[0].name, objective.parameters().coordinates()[0].name);
  for (int j = 0; j < 2; ++j) {
    const ParameterProfile& p = profiles[static_cast<std::size_t>(j)];
    EXPECT_EQ(p.u, (std::vector<double>{0, 0.5, 1}));
    double lo = f, hi = f;
    for (std::size_t k = 0; k < 3; ++k) {
      Eigen::Vector2d v = u;
      v[j] = p.u[k];
      const Evaluation e = objective.Evaluate(v);
      EXPECT_EQ(p.f[k], e.value);
      EXPECT_EQ(p.values[k], e.values[j]);
      lo = std::min(lo, e.value);
      hi = std::max(hi, e.value);
    }
    EXPECT_EQ(p.range, hi - lo);
    EXPECT_EQ(p.threshold, std::max(3 * noise, 1e-6 * std::abs(f)));
    EXPECT_EQ(p.identified, p.range > p.threshold);
  }
  // The run-outs see mu_min: from 0.1 to 0.9 they change by far more than the noise given.
  EXPECT_TRUE(profiles[0].identified);
  EXPECT_NEAR(profiles[0].values.front(), 0.1, 1e-12);
  EXPECT_NEAR(profiles[0].values.back(), 0.9, 1e-12);
  // The rocks-per-run rule on each profile: R (t / r)^2 with the release's rocks per run, and
  // whether the range is within what noise alone spans over 3 values (f(u) and the points 0 and
  // 1; the point 0.5 is u itself, the same rocks, the same value).
  const double rocks = static_cast<double>(objective.release().rocks_per_release);
  for (const ParameterProfile& p : profiles) {
    EXPECT_EQ(p.rocks_to_identify, RocksToIdentify(p.range, p.threshold, rocks)) << p.name;
    EXPECT_EQ(p.within_noise, p.range <= NoiseOnlyRange(3, noise)) << p.name;
  }
  // mu_min's range is far above the threshold: far fewer rocks would do.
  EXPECT_LT(profiles[0].rocks_to_identify, rocks);
  EXPECT_FALSE(profiles[0].within_noise);
  // A noise level above any change leaves every parameter unidentified, its range within noise.
  for (const ParameterProfile& p : ProfileParameters(objective, u, f, 1e9, options)) {
    EXPECT_FALSE(p.identified) << p.name;
    EXPECT_TRUE(p.within_noise) << p.name;
  }
  // Without a noise (a smooth objective) the threshold is the relative floor: no rule applies.
  for (const ParameterProfile& p : ProfileParameters(objective, u, f, 0, options)) {
    EXPECT_TRUE(std::isnan(p.rocks_to_identify)) << p.name;
    EXPECT_FALSE(p.within_noise) << p.name;
  }
}

// With many points, what noise alone spans exceeds 3 x the noise (d2(10) = 3.08): a range above
// 3 x the noise but within that span is not identified, and its rule is hedged.
TEST(ProfileParameters, ARangeWithinWhatNoiseSpansOverManyPointsIsNotIdentified) {
  const Objective& objective = TwoParameterObjective();
  const Eigen::Vector2d u(0.5, 0.5);
  const double f = objective.Evaluate(u).value;
  ProfileOptions options;
  options.points = 20;  // at k / 19, never u: 21 values with f(u)
  const double range = ProfileParameters(objective, u, f, 1e-9, options)[0].range;
  ASSERT_GT(range, 0);
  const double noise = range / 3.4;  // 3 x noise < range < d2(21) x noise = 3.78 x noise
  ASSERT_GT(range, options.noise_multiple * noise);
  ASSERT_LT(range, NoiseOnlyRange(21, noise));
  const ParameterProfile p = ProfileParameters(objective, u, f, noise, options)[0];
  EXPECT_EQ(p.range, range);
  EXPECT_EQ(p.threshold, NoiseOnlyRange(21, noise));
  EXPECT_FALSE(p.identified);
  EXPECT_TRUE(p.within_noise);
  EXPECT_EQ(p.rocks_to_identify,
            RocksToIdentify(range, p.threshold,
                            static_cast<double>(objective.release().rocks_per_release)));
}

// The rule's premise, that the level falls with the rocks, holds for the seeds' spread and for
// the roughness at a small step, not for the roughness at a step where the objective's smooth
// change is part of it.
TEST(RoughnessReport, TheLevelIsSamplingNoiseFromTheSeedsOrAtASmallStep) {
  RoughnessReport r;
  r.steps = {1e-2, 1e-1};
  r.noise = 0.12;
  EXPECT_FALSE(r.LevelIsSamplingNoise());  // no seeds, a large step
  r.seed_sd = 0.03;
  EXPECT_FALSE(r.LevelIsSamplingNoise());  // the level is the roughness at 1e-2
  r.seed_sd = 0.2;
  EXPECT_TRUE(r.LevelIsSamplingNoise());  // the level is the seeds' spread
  r.seed_sd = 0.03;
  r.steps = {1e-3, 1e-2};
  EXPECT_TRUE(r.LevelIsSamplingNoise());
  r.steps = {1.5e-3};
  EXPECT_FALSE(r.LevelIsSamplingNoise());
}

TEST(RocksToIdentify, ScalesTheRocksByTheSquaredRatioOfThresholdToRange) {
  EXPECT_DOUBLE_EQ(RocksToIdentify(0.41, 0.99, 8), 8 * (0.99 / 0.41) * (0.99 / 0.41));
  EXPECT_DOUBLE_EQ(RocksToIdentify(2, 1, 20), 5);     // twice the threshold: a quarter of the rocks
  EXPECT_TRUE(std::isnan(RocksToIdentify(0, 1, 8)));  // a flat profile: no number of rocks
  EXPECT_TRUE(std::isnan(RocksToIdentify(1, 0, 8)));
}

// d2(n), the expected range of n standard normal draws: 2 / sqrt(pi) exactly for n = 2, and the
// tabulated values of quality control (Tippett 1925; ASTM STP 15D, Table 49), given to 3 decimals,
// hence the tolerance of half their last digit.
TEST(NoiseOnlyRange, IsTheExpectedRangeOfNormalDraws) {
  EXPECT_NEAR(NoiseOnlyRange(2, 1), 2 / std::sqrt(M_PI), 1e-9);
  const std::pair<int, double> table[] = {
      {3, 1.693}, {4, 2.059}, {5, 2.326}, {10, 3.078}, {25, 3.931}};
  for (const auto& [n, d2] : table) EXPECT_NEAR(NoiseOnlyRange(n, 1), d2, 5e-4) << n;
  EXPECT_NEAR(NoiseOnlyRange(5, 0.2), 0.2 * NoiseOnlyRange(5, 1), 1e-15);
  EXPECT_EQ(NoiseOnlyRange(1, 1), 0);
}

// The premise of the rule: the objective's spread over release seeds falls as 1/sqrt(rocks per
// run). 32 seeds at 4 and at 16 rocks per run, on the synthetic run-outs: the ratio of the two
// standard deviations is 2 in expectation. Each sd over 32 seeds has a relative standard error
// of about 1/sqrt(2 x 31) = 0.127, so the log of the ratio one of 0.18; the band is 3 of them,
// [2 e^-0.54, 2 e^0.54] = [1.17, 3.43]. It fails if the noise did not fall with the rocks
// (ratio 1) or fell as 1/rocks (ratio 4).
TEST(RocksToIdentify, TheObjectivesSpreadOverSeedsFallsAsOneOverTheRootOfTheRocks) {
  const auto spread = [](long rocks) {
    ensemble::ReleaseSpec release = Problem().release;
    release.rocks_per_release = rocks;
    const Objective objective(Problem().scene, release, Problem().observations,
                              {testing::Spec("medium_hard", GroundField::kMuMin, 0.1, 0.9)},
                              ObjectiveOptions{});
    const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.5);
    constexpr int kSeeds = 32;
    double sum = 0, sum2 = 0;
    for (int k = 1; k <= kSeeds; ++k) {
      const double f = objective.EvaluateWithSeed(u, release.seed + 100 + k).value;
      sum += f;
      sum2 += f * f;
    }
    return std::sqrt((sum2 - sum * sum / kSeeds) / (kSeeds - 1));
  };
  const double ratio = spread(4) / spread(16);
  RecordProperty("sd_ratio", std::to_string(ratio));
  EXPECT_GT(ratio, 1.17);
  EXPECT_LT(ratio, 3.43);
}

}  // namespace
}  // namespace talus::calibration
