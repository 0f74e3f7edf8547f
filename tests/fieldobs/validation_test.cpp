// Validation scores: by hand on made-up samples, and the calibration of the whole chain on
// observations drawn from the model itself.

#include "fieldobs/validation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "ensemble/runner.hpp"
#include "solver/shapes.hpp"

namespace talus::fieldobs {
namespace {

// "r7" (GCC 12 warns wrongly about std::string concatenation here).
std::string Id(const char* prefix, int index) {
  char id[32];
  std::snprintf(id, sizeof id, "%s%d", prefix, index);
  return id;
}

// Samples of `runs` runs with the given runouts per run (run ids "r0", "r1", ...).
struct Fake {
  ensemble::ReleaseSpec release;
  std::unique_ptr<EnsembleSamples> samples;
  explicit Fake(const std::vector<std::vector<double>>& runouts) {
    for (std::size_t r = 0; r < runouts.size(); ++r) {
      ensemble::ReleaseRun run;
      run.id = Id("r", static_cast<int>(r));
      release.runs.push_back(run);
    }
    release.rocks_per_release = static_cast<long>(runouts[0].size());
    samples = std::make_unique<EnsembleSamples>(release);
    long rock = 0;
    for (std::size_t r = 0; r < runouts.size(); ++r)
      for (double v : runouts[r]) {
        ensemble::RockOutcome out;
        out.rock = rock++;
        out.release = static_cast<int>(r);
        out.result.runout_m = v;
        out.result.final_state.position_m = Eigen::Vector3d(v, 0, 0);
        samples->OnRock(out);
      }
  }
};

TEST(Validate, ScoresBaselinesAndSkillsByHand) {
  const Fake model({{10, 12, 14}, {20, 22, 24}});
  const Fake reference({{0, 1, 2}, {0, 1, 2}});
  ObservationSet obs;
  obs.scalars.push_back({Quantity::kRunout, "r0", 12, "a:2"});
  obs.scalars.push_back({Quantity::kRunout, "r1", 21, "a:3"});
  obs.scalars.push_back({Quantity::kRunout, "missing", 5, "a:4"});
  obs.deposits.push_back({"r0", Eigen::Vector2d(12, 0), std::nullopt, "d:2"});
  const ValidationReport report = Validate(obs, *model.samples, reference.samples.get());
  ASSERT_EQ(report.observations.size(), 4u);
  const ObservationScore& a = report.observations[0];
  EXPECT_TRUE(a.scored);
  EXPECT_DOUBLE_EQ(a.score, CrpsEnsemble(std::vector<double>{10, 12, 14}, 12));
  EXPECT_DOUBLE_EQ(a.reference_score, CrpsEnsemble(std::vector<double>{0, 1, 2}, 12));
  // Leave-one-out climatology: the other runout observations (21 and 5).
  EXPECT_DOUBLE_EQ(a.climatology_score, CrpsEnsemble(std::vector<double>{21, 5}, 12));
  EXPECT_DOUBLE_EQ(a.bias, 0);
  EXPECT_TRUE(a.inside_90);
  EXPECT_FALSE(report.observations[2].scored);
  EXPECT_EQ(report.observations[2].not_scored, "no run 'missing' in the scene");
  // The deposit on the line of the simulated end positions: the energy score is the CRPS.
  EXPECT_NEAR(report.observations[3].score, a.score, 1e-12);
  ASSERT_EQ(report.kinds.size(), 2u);
  const KindSummary& runout = report.kinds[0];
  EXPECT_EQ(runout.observations, 3);
  EXPECT_EQ(runout.scored, 2);
  const double mean = 0.5 * (a.score + report.observations[1].score);
  EXPECT_DOUBLE_EQ(runout.mean_score, mean);
  EXPECT_DOUBLE_EQ(runout.skill_vs_reference,
                   1 - mean / (0.5 * (a.reference_score + report.observations[1].reference_score)));
  EXPECT_GT(runout.skill_vs_reference, 0.9);  // the model is far better than the reference
  EXPECT_EQ(report.observations_scored, 3);
}

TEST(Validate, TooFewMembersIsNotScoredAndSaysWhy) {
  const Fake model(std::vector<std::vector<double>>{{10.0}});
  ObservationSet obs;
  obs.scalars.push_back({Quantity::kRunout, "r0", 12, "a:2"});
  const ValidationReport report = Validate(obs, *model.samples, nullptr);
  EXPECT_FALSE(report.observations[0].scored);
  EXPECT_EQ(report.observations[0].not_scored, "only 1 simulated values");
  EXPECT_TRUE(std::isnan(report.kinds[0].mean_score));
}

// The whole chain on observations drawn from the model itself: 60 runs of a 0.4 m cube on a
// 35 degree slope (each run starting elsewhere across the slope, with its own speed), simulated
// with 19 random orientations per run; the "observation" of each run is one more rock of the same
// run with another seed. The observed runout's PIT is then uniform: chi-square on 10 bins passes
// at the 0.1 % level. A model with another friction (mu 0.7 instead of medium_hard's ramp of
// 0.40 .. 2.0) is biased, and the same test must fail it (p < 1e-6). The seeds are fixed, so the
// test is deterministic; measured: p = 0.25, mean CRPS 2.54 m (same model) and p = 9.5e-29,
// mean CRPS 6.61 m (biased).
TEST(Validate, PitOfObservationsDrawnFromTheModelIsUniform) {
  Scene scene;
  PlaneSpec plane{35, 30, 40, 80, 1};
  scene.terrain = Terrain(MakePlaneHeightfield(plane), scene.ground.IndexOfName("medium_hard"));
  scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.3), 2700);
  scene.options.max_time_s = 6;  // rocks still moving then are scored where they are, alike
  ensemble::ReleaseSpec release;
  for (int r = 0; r < 60; ++r) {
    ensemble::ReleaseRun run;
    run.id = Id("run", r);
    run.xy_m = {2.0 + 0.05 * r, -35.0 + 1.2 * r};
    run.height_m = 0.5 + 0.02 * r;
    run.velocity_m_s = {1.0 + 0.1 * (r % 7), 0, 0};
    release.runs.push_back(run);
  }
  release.rocks_per_release = 19;
  release.seed = 11;
  ensemble::EnsembleOptions options;
  options.threads = 2;
  EnsembleSamples model(release);
  ensemble::RunEnsemble(scene, release, options, &model);

  ensemble::ReleaseSpec truth_release = release;
  truth_release.rocks_per_release = 1;
  truth_release.seed = 12345;
  EnsembleSamples truth(truth_release);
  ensemble::RunEnsemble(scene, truth_release, options, &truth);
  ObservationSet obs;
  for (const ensemble::ReleaseRun& run : release.runs)
    obs.scalars.push_back(
        {Quantity::kRunout, run.id, truth.Values(Quantity::kRunout, run.id)[0], run.id});
  const ValidationReport same = Validate(obs, model, nullptr, {7, 2});
  ASSERT_EQ(same.kinds[0].scored, 60);
  ASSERT_EQ(same.kinds[0].pit.counts.size(), 10u);
  EXPECT_GT(same.kinds[0].pit.p_value, 1e-3) << same.FullReport();

  Scene biased = scene;
  const int g = biased.ground.IndexOfName("medium_hard");
  biased.ground.mutable_params(g).mu_min = 0.7;
  biased.ground.mutable_params(g).mu_max = 0.7;
  EnsembleSamples wrong(release);
  ensemble::RunEnsemble(biased, release, options, &wrong);
  const ValidationReport other = Validate(obs, wrong, nullptr, {7, 2});
  EXPECT_LT(other.kinds[0].pit.p_value, 1e-6) << other.FullReport();
  EXPECT_GT(other.kinds[0].mean_score, same.kinds[0].mean_score);
}

}  // namespace
}  // namespace talus::fieldobs
