// Seed refits: their options' checks, the combination with the bootstrap (the formula of
// seeds.hpp, value for value), and that they are bit-identical for any thread count. What they
// give on the recovery problems is checked in recovery_test.cpp and bootstrap_test.cpp.

#include "calibration/seeds.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

TEST(SeedRefitOptions, DefaultsAreValidAndAbsurdValuesAreRefusedWithTheKey) {
  std::string why;
  EXPECT_TRUE(SeedRefitOptions().IsValid(&why)) << why;
  SeedRefitOptions o;
  o.seeds = 1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("seeds = 1 must be 0 (off) or in 2 .."), std::string::npos) << why;
  o.seeds = -3;
  EXPECT_FALSE(o.IsValid(&why));
  o.seeds = SeedRefitOptions::kMaxSeeds + 1;
  EXPECT_FALSE(o.IsValid(&why));
  o.seeds = 4;
  EXPECT_TRUE(o.IsValid(&why)) << why;
}

// 8 runs x 3 rocks of the run-outs of bootstrap_test.cpp, mu_min (0.1 .. 0.9) at 0.5.
struct SmallProblem {
  testing::SyntheticRunouts p{8, 3, 0.5, 0.5, ViscousReading::kContactFriction};
  Objective With(int threads) const {
    ParameterSpec mu;
    mu.category = "medium_hard";
    mu.field = GroundField::kMuMin;
    mu.lower = 0.1;
    mu.upper = 0.9;
    ObjectiveOptions options;
    options.threads = threads;
    return Objective(p.scene, p.release, p.observations, {mu}, options);
  }
};

BootstrapOptions SmallBootstrap() {
  BootstrapOptions options;
  options.resamples = 10;
  options.refit_evaluations = 6;
  options.resolution = 0.02;
  return options;
}

// Each seed's refit runs one after the other, each evaluation bit-identical for any thread count:
// so are the refits, their spread and the combination. Other seeds move the fit (sd > 0), the
// seeds are the release's + 1 .. + S, and the combination is the formula of seeds.hpp. The
// refits start at mu_min 0.3 (truth 0.5), so that every seed's refit moves.
TEST(SeedRefits, AreBitIdenticalForAnyThreadCountAndCombineAsStated) {
  static const SmallProblem small;
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, (0.3 - 0.1) / 0.8);
  const BootstrapOptions options = SmallBootstrap();
  const Objective one = small.With(1), two = small.With(2);
  const Bootstrap b = BootstrapOverRuns(one, u, options);
  ASSERT_GT(b.standard_error[0], 0.01);  // measured: 0.021 (the combination is checked below)
  const SeedRefits a = RefitWithOtherSeeds(one, b, options, {3});
  const SeedRefits c = RefitWithOtherSeeds(two, b, options, {3});  // the bootstrap is tested alike
  std::printf("%s%s", b.Report().c_str(), a.Report().c_str());
  EXPECT_EQ(a.refits, c.refits);
  EXPECT_EQ(a.combined_standard_error, c.combined_standard_error);
  EXPECT_EQ(a.lower, c.lower);
  ASSERT_EQ(a.release_seeds.size(), 3u);
  EXPECT_EQ(a.release_seeds[0], small.p.release.seed + 1);
  EXPECT_EQ(a.release_seeds[2], small.p.release.seed + 3);
  EXPECT_GT(a.evaluations, 3);
  ASSERT_GT(a.sd[0], 0.01);  // measured: 0.028
  // sd from 3 values, inflated by its own standard error 1/sqrt(2 (3 - 1)) = 0.5.
  EXPECT_DOUBLE_EQ(a.seed_standard_error[0], 1.5 * a.sd[0]);
  EXPECT_DOUBLE_EQ(a.combined_standard_error[0],
                   std::sqrt(b.standard_error[0] * b.standard_error[0] +
                             a.seed_standard_error[0] * a.seed_standard_error[0]));
  // The 95 % interval: each side of the bootstrap's widened by 1.959964 x the seeds' part in
  // quadrature, about the start (0.3), within the bounds.
  EXPECT_NEAR(a.fitted[0], 0.3, 1e-12);
  const double seeds = 1.959964 * a.seed_standard_error[0];
  EXPECT_NEAR(a.lower[0], std::max(0.1, 0.3 - std::hypot(std::max(0.0, 0.3 - b.lower[0]), seeds)),
              1e-6);
  EXPECT_NEAR(a.upper[0], std::min(0.9, 0.3 + std::hypot(std::max(0.0, b.upper[0] - 0.3), seeds)),
              1e-6);
}

TEST(SeedRefits, InvalidOptionsAreRefusedBeforeAnyEvaluation) {
  static const SmallProblem small;
  const Objective objective = small.With(1);
  EXPECT_THROW(RefitWithOtherSeeds(objective, Bootstrap{}, SmallBootstrap(), {1}),
               std::invalid_argument);
  BootstrapOptions refit = SmallBootstrap();
  refit.resolution = 0.5;
  EXPECT_THROW(RefitWithOtherSeeds(objective, Bootstrap{}, refit, {3}), std::invalid_argument);
}

}  // namespace
}  // namespace talus::calibration
