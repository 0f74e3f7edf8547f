// Validation scores: by hand on made-up samples, and the calibration of the whole chain on
// observations drawn from the model itself.

#include "fieldobs/validation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <tuple>
#include <vector>

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

// 40 000 runout observations took 34 s and 3 million did not finish in 120 s: each one's
// leave-one-out climatology was a sorted copy of all the others. 200 000 (of the whole scene,
// against a small ensemble) now take about a second; the quadratic form would take hours. The
// climatology of one of them is still the CRPS against all the others.
TEST(Validate, ManyObservationsTakeTimeInProportion) {
  const Fake model({{50, 52, 54, 56}, {51, 53, 55, 57}});
  ObservationSet obs;
  for (int k = 0; k < 200000; ++k)
    obs.scalars.push_back(
        {Quantity::kRunout, "", 40.0 + (k * 7919 % 1000) * 0.03, "t:" + Id("", k)});
  const auto t0 = std::chrono::steady_clock::now();
  const ValidationReport report = Validate(obs, *model.samples, nullptr);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(report.observations.size(), obs.scalars.size());
  EXPECT_LT(seconds, 60.0);  // a wide margin for sanitizer builds and loaded machines
  std::vector<double> others;
  for (std::size_t k = 1; k < obs.scalars.size(); ++k) others.push_back(obs.scalars[k].value);
  const double direct = CrpsEnsemble(others, obs.scalars[0].value);
  // Rounding only: about n eps = 2e-11 of the score from the prefix sums (scores_test.cpp).
  EXPECT_NEAR(report.observations[0].climatology_score, direct, 1e-9 * direct);
}

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

// Trajectory segments of a rock in free flight: the observed samples are the closed-form parabola
// (200 Hz, as the Chant Sura reconstructions), the simulated rocks start in the same state with
// random orientations. Free flight does not depend on the orientation, the midpoint scheme is
// exact for the parabola, and for a cube (isotropic inertia) torque-free rotation keeps |omega|
// constant (the scheme conserves energy exactly), so every simulated rock reproduces the
// observed largest speed and jump height up to the sampling (the simulated window ends within half
// a step, 1 ms, of the observed one: |dv| <= g * 1 ms = 0.01 m/s; the jump height's maximum is
// sampled at 2 ms vs 5 ms: |dz| <= g (2.5 ms)^2 / 2 = 3e-5 m) and the mean angular speed exactly.
TEST(Validate, FreeFlightSegmentsAreReproduced) {
  Scene scene;
  PlaneSpec plane{0, 0.0, 60, 60, 1};  // flat ground at z = 0
  scene.terrain = Terrain(MakePlaneHeightfield(plane), scene.ground.IndexOfName("medium"));
  scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.4), 2700);
  scene.options.max_time_s = 3;
  ensemble::ReleaseSpec release;
  ensemble::ReleaseRun run;
  run.id = "seg";
  run.xy_m = {5, 0};
  run.z_m = 10;
  run.velocity_m_s = {4, 1, 3};
  run.angular_velocity_rad_s = {0, 6, 2};
  release.runs = {run};
  release.rocks_per_release = 8;
  // Observed: 0.5 s of the parabola at 200 Hz.
  std::string csv =
      "trajectory_id,time_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,omega_x_radps,"
      "omega_y_radps,omega_z_radps\n";
  double observed_speed = 0, observed_jump = 0;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.005 * k, vz = 3 - 9.81 * t, z = 10 + 3 * t - 0.5 * 9.81 * t * t;
    char line[256];
    std::snprintf(line, sizeof line, "seg,%.3f,%.9f,%.9f,%.9f,4,1,%.9f,0,6,2\n", t, 5 + 4 * t, t, z,
                  vz);
    csv += line;
    observed_speed = std::max(observed_speed, std::sqrt(17 + vz * vz));
    observed_jump = std::max(observed_jump, z);
  }
  ObservationSet obs;
  ReadTrajectories(CsvTable::Parse(csv, "traj.csv"), TableColumns{}, scene.terrain, obs);
  ASSERT_EQ(obs.scalars.size(), 3u);
  EXPECT_NEAR(obs.scalars[0].value, observed_speed, 1e-6);
  EXPECT_NEAR(obs.scalars[1].value, std::sqrt(40.0), 1e-9);
  EXPECT_NEAR(obs.scalars[2].value, observed_jump, 1e-6);
  EXPECT_NEAR(obs.scalars[0].window_s, 0.5, 1e-12);

  ensemble::EnsembleOptions options;
  options.threads = 2;
  options.extra_recorders.push_back(SegmentRecorders(scene.terrain, SegmentWindows(obs, release)));
  EnsembleSamples simulated(release);
  ensemble::RunEnsemble(scene, release, options, &simulated);
  const ValidationReport report = Validate(obs, simulated, nullptr);
  ASSERT_EQ(report.observations_scored, 3) << report.FullReport();
  const std::vector<double> speeds = simulated.Values(Quantity::kSegmentMaxSpeed, "seg");
  ASSERT_EQ(speeds.size(), 8u);
  for (double v : speeds) EXPECT_NEAR(v, observed_speed, 0.01);
  for (double w : simulated.Values(Quantity::kSegmentMeanAngularSpeed, "seg"))
    EXPECT_NEAR(w, std::sqrt(40.0), 1e-9);
  for (double z : simulated.Values(Quantity::kSegmentMaxJumpHeight, "seg"))
    EXPECT_NEAR(z, observed_jump, 3e-5);
  EXPECT_LT(report.observations[0].score, 0.01);  // CRPS of a near-exact ensemble, m/s
}

// Zones on a block sliding down a 30 degree incline with constant Coulomb friction mu = 0.3 (no
// viscous term): it slides at a = g (sin 30 - mu cos 30) = 2.356 m/s^2 (closed form; the solver's
// incline test holds it to 1e-6), so it crosses a line 10 m downhill (horizontally) at
// v = sqrt(2 a s), s = 10 / cos 30, = 7.376 m/s; its centre of mass stays 0.25 m above the slope. A
// polygon from 10 to 20 m downhill sees it as fast as when it leaves: sqrt(2 a 20 / cos 30), to
// within one step (a dt = 0.005 m/s). A line beside its path is never crossed.
TEST(Validate, ZoneCrossingsOfASlidingBlockFollowTheClosedForm) {
  Scene scene;
  PlaneSpec plane{30, 60, 10, 40, 1};
  const int test = scene.ground.Set({"test", 100, GroundParams{0.3, 0.3, 150, 2, 0}});
  scene.terrain = Terrain(MakePlaneHeightfield(plane), test);
  scene.rock = MakeRockShape(MakeBox(1.0, 1.0, 0.5), 2700);
  scene.options.max_time_s = 6;
  ensemble::ReleaseSpec release;
  ensemble::ReleaseRun run;
  run.id = "slide";
  run.xy_m = {5, 0};
  run.height_m = 0;  // raised until the box rests on the slope
  run.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitY()));
  release.runs = {run};
  release.rocks_per_release = 3;
  ObservationSet obs;
  obs.zones.push_back({"line10", false, {{15, -10}, {15, 10}}});
  obs.zones.push_back({"band", true, {{15, -10}, {25, -10}, {25, 10}, {15, 10}}});
  obs.zones.push_back({"aside", false, {{15, 5}, {15, 10}}});
  const double a = 9.81 * (0.5 - 0.3 * std::cos(M_PI / 6));
  const double v10 = std::sqrt(2 * a * 10 / std::cos(M_PI / 6));
  const double v20 = std::sqrt(2 * a * 20 / std::cos(M_PI / 6));
  for (const auto& [zone, q, value] :
       std::vector<std::tuple<int, Quantity, double>>{{0, Quantity::kZoneSpeed, v10},
                                                      {0, Quantity::kZoneJumpHeight, 0.25},
                                                      {0, Quantity::kZonePassed, 1},
                                                      {1, Quantity::kZoneSpeed, v20},
                                                      {2, Quantity::kZonePassed, 0}}) {
    ScalarObservation o{q, "slide", value, "z"};
    o.zone = zone;
    obs.scalars.push_back(o);
  }
  ensemble::EnsembleOptions options;
  options.extra_recorders.push_back(ZoneRecorders(obs.zones));
  EnsembleSamples simulated(release);
  ensemble::RunEnsemble(scene, release, options, &simulated);
  const auto speeds = simulated.Values(Quantity::kZoneSpeed, "slide", 0);
  ASSERT_EQ(speeds.size(), 3u);
  for (double v : speeds) EXPECT_NEAR(v, v10, 0.01);
  for (double h : simulated.Values(Quantity::kZoneJumpHeight, "slide", 0))
    EXPECT_NEAR(h, 0.25, 1e-3);
  for (double v : simulated.Values(Quantity::kZoneSpeed, "slide", 1)) EXPECT_NEAR(v, v20, 0.01);
  EXPECT_EQ(simulated.Values(Quantity::kZonePassed, "slide", 2), std::vector<double>(3, 0.0));
  EXPECT_TRUE(simulated.Values(Quantity::kZoneSpeed, "slide", 2).empty());  // never reached
  const ValidationReport report = Validate(obs, simulated, nullptr);
  EXPECT_EQ(report.observations_scored, 5);
  for (const ObservationScore& s : report.observations) EXPECT_LT(s.score, 0.01) << s.kind;
}

TEST(Observations, TrajectorySegmentsNeedIncreasingTimesAndTwoSamples) {
  const Terrain flat(MakePlaneHeightfield(PlaneSpec{0, 0.0, 10, 10, 1}), 0);
  ObservationSet set;
  const auto error = [&](const std::string& text) {
    try {
      ReadTrajectories(CsvTable::Parse(text, "t.csv"), TableColumns{}, flat, set);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("trajectory_id,time_s,x_m,y_m,z_m,speed_mps\na,0,1,1,1,2\na,0,1,1,1,2\n")
                .find("t.csv:3: column 'time_s': times of run 'a' must increase"),
            std::string::npos);
  EXPECT_NE(error("trajectory_id,time_s,x_m,y_m,z_m,speed_mps\na,0,1,1,1,2\n")
                .find("t.csv:2: run 'a' has a single trajectory sample"),
            std::string::npos);
  EXPECT_NE(error("trajectory_id,time_s,x_m,y_m,z_m\na,0,1,1,1\n").find("missing column 'vx_mps'"),
            std::string::npos);
  EXPECT_NE(error("trajectory_id,time_s,x_m,y_m,z_m,speed_mps,omega_x_radps,omega_y_radps,"
                  "omega_z_radps\na,0,1,1,1,2,1,0,0\na,1,1,1,1,2,1,x,0\n")
                .find("t.csv:3: column 'omega_y_radps': 'x' is not a finite number"),
            std::string::npos);
}

// Segments whose samples lack angular velocity (the Chant Sura EOTA111 block: NaN) keep their
// speed and jump height; the angular mean is only over segments every sample of which has it.
TEST(Observations, TrajectorySegmentsWithoutAngularVelocityGiveNoAngularSpeed) {
  const Terrain flat(MakePlaneHeightfield(PlaneSpec{0, 0.0, 10, 10, 1}), 0);
  ObservationSet set;
  ReadTrajectories(
      CsvTable::Parse("trajectory_id,time_s,x_m,y_m,z_m,speed_mps,omega_x_radps,omega_y_radps,"
                      "omega_z_radps\n"
                      "full,0,1,1,1,2,3,4,0\nfull,1,1,1,1,2,0,0,1\n"
                      "none,0,1,1,1,3,NaN,NaN,NaN\nnone,1,1,1,1,3,NaN,NaN,NaN\n"
                      "part,0,1,1,1,4,1,0,0\npart,1,1,1,1,4,,,\n",
                      "t.csv"),
      TableColumns{}, flat, set);
  std::vector<std::string> angular_runs;
  int speeds = 0;
  for (const ScalarObservation& o : set.scalars) {
    if (o.quantity == Quantity::kSegmentMeanAngularSpeed) {
      angular_runs.push_back(o.run);
      EXPECT_NEAR(o.value, 3.0, 1e-15);  // (|(3,4,0)| + |(0,0,1)|) / 2
    }
    speeds += o.quantity == Quantity::kSegmentMaxSpeed;
  }
  EXPECT_EQ(angular_runs, std::vector<std::string>{"full"});
  EXPECT_EQ(speeds, 3);
}

// Per block: the scored observations of each block's runs, their mean bias and score by hand; an
// observation not scored, of a deposit (no bias), or of a run the release does not have is left
// out, and a run without a block counts under "[rock]".
TEST(BiasByBlock, MeansOverEachBlocksRunsByHand) {
  ensemble::ReleaseSpec release;
  release.blocks = {{"St. Leonard", nullptr, {}, {}}, {"Plate", nullptr, {}, {}}};
  for (const auto& [id, block] : std::vector<std::pair<std::string, int>>{
           {"a", 0}, {"b", 1}, {"c", 0}, {"d", -1}}) {
    ensemble::ReleaseRun run;
    run.id = id;
    run.block = block;
    release.runs.push_back(run);
  }
  const auto score = [](const std::string& run, const std::string& kind, double bias, double crps,
                        bool scored = true) {
    ObservationScore s;
    s.run = run;
    s.kind = kind;
    s.unit = "m";
    s.bias = bias;
    s.score = crps;
    s.scored = scored;
    return s;
  };
  const std::vector<ObservationScore> scores = {
      score("a", "runout", 30, 20), score("c", "runout", 10, 8),  score("b", "runout", -20, 15),
      score("d", "runout", 4, 3),   score("b", "runout", 99, 9, false),
      score("e", "runout", 50, 40), score("a", "deposit", kNaN, 12)};
  const std::vector<BlockBias> biases = BiasByBlock(scores, release);
  ASSERT_EQ(biases.size(), 3u);
  EXPECT_EQ(biases[0].block, "St. Leonard");
  EXPECT_EQ(biases[0].scored, 2);
  EXPECT_EQ(biases[0].mean_bias, 20);
  EXPECT_EQ(biases[0].runs, 2);
  EXPECT_DOUBLE_EQ(biases[0].bias_standard_error, 10);  // biases 30, 10: sd 14.14 / sqrt 2
  EXPECT_EQ(biases[0].mean_score, 14);
  EXPECT_EQ(biases[1].block, "Plate");
  EXPECT_EQ(biases[1].scored, 1);
  EXPECT_EQ(biases[1].mean_bias, -20);
  EXPECT_TRUE(std::isnan(biases[1].bias_standard_error));  // one run: no spread
  EXPECT_EQ(biases[2].block, "[rock]");
  EXPECT_EQ(biases[2].mean_bias, 4);
  EXPECT_EQ(biases[2].kind, "runout");
  EXPECT_EQ(biases[2].unit, "m");
}

// Observations of one run are not independent: the standard error is clustered by run. Run a
// holds biases 10 and 30, run c 0 and run d -40 (all of one block): mean 0, run sums S = 40, 0,
// -40, se^2 = 3/2 * (1600 + 0 + 1600) / 16 = 300. Counted as four independent observations it
// would be sd / 2 = sqrt(1400 / 3) / 2 = 10.8 instead of 17.3.
TEST(BiasByBlock, StandardErrorIsClusteredByRun) {
  ensemble::ReleaseSpec release;
  release.blocks = {{"B", nullptr, {}, {}}};
  for (const std::string id : {"a", "c", "d"}) {
    ensemble::ReleaseRun run;
    run.id = id;
    run.block = 0;
    release.runs.push_back(run);
  }
  const auto score = [](const std::string& run, double bias) {
    ObservationScore s;
    s.run = run;
    s.kind = "zone_speed";
    s.unit = "m/s";
    s.bias = bias;
    s.score = 1;
    s.scored = true;
    return s;
  };
  const std::vector<BlockBias> biases =
      BiasByBlock({score("a", 10), score("a", 30), score("c", 0), score("d", -40)}, release);
  ASSERT_EQ(biases.size(), 1u);
  EXPECT_EQ(biases[0].scored, 4);
  EXPECT_EQ(biases[0].runs, 3);
  EXPECT_DOUBLE_EQ(biases[0].mean_bias, 0);
  EXPECT_NEAR(biases[0].bias_standard_error, std::sqrt(300.0), 1e-12);
}

}  // namespace
}  // namespace talus::fieldobs
