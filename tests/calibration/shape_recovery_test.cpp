// Shape and ground fitted together (docs/calibration.md, "Shape parameters"): run-outs of two
// blocks of different shape on a plane, drawn by Talus itself with a known roughness of one block
// and a known mu_min of the ground, are fitted back jointly from a distant start through the
// calibration call (Calibrate, Ceres), and the stated intervals must hold the truth. The scene is
// a scene file with a blocks file, as a user writes it.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "calibration/calibrate.hpp"
#include "io/scene_file.hpp"
#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

namespace fs = std::filesystem;

constexpr int kRuns = 48;
constexpr double kTruthMu = 0.5, kTruthRoughness = 0.3;   // of the drawn observations
constexpr double kStartMu = 0.8, kStartRoughness = 0.05;  // where the fit starts
constexpr double kMuLower = 0.1, kMuUpper = 0.9, kRoughnessUpper = 0.5;

// 48 runs down a 28 degree plane (30 m slope, 40 m flat), alternately a rough rock block ("round",
// 0.45 x 0.40 x 0.35 m, 60 kg) and a box ("slab", 0.5 x 0.4 x 0.2 m, 108 kg), each from its own
// place, 0.5 to 0.68 m up with a push of 1 to 1.6 m/s downslope; 4 rocks per run, stopped at 10 s;
// medium_hard with kappa 0.05 1/m, so that friction stays near mu_min (as SyntheticRunouts).
// The slab slides and stops on the slope: its run-out measures mu_min; the rock rolls, and the
// rougher its hull the sooner it stops: its run-out measures its roughness.
io::SceneFile LoadTwoBlockScene() {
  const fs::path dir = fs::temp_directory_path() / "talus_shape_recovery";
  fs::create_directories(dir);
  std::ofstream(dir / "blocks.csv") << "block_id,mass_kg,size_x_m,size_y_m,size_z_m,shape\n"
                                       "round,60,0.45,0.40,0.35,rock\n"
                                       "slab,108,0.5,0.4,0.2,box\n";
  std::ofstream runs(dir / "runs.csv");
  runs << "trajectory_id,x_m,y_m,height_m,vx_mps,block_id\n";
  for (int r = 0; r < kRuns; ++r)
    runs << "run" << r << "," << 2.0 + 0.025 * r << "," << -35.0 + 70.0 * r / kRuns << ","
         << 0.5 + 0.02 * (r % 10) << "," << 1.0 + 0.1 * (r % 7) << "," << (r % 2 ? "slab" : "round")
         << "\n";
  runs.close();
  // Whole steps (impact_substeps = 1) and the Gauss-Seidel contact solve, the scheme the fits'
  // spread over draws was measured with (before the free rotation was written out, this draw fitted
  // mu_min 0.523 under the default sub-steps and 0.536 under the default block on stall, both
  // within it; see the test's comment).
  std::ofstream(dir / "scene.toml") << R"([terrain]
plane = { slope_deg = 28, slope_length_m = 30, runout_m = 40, width_m = 80, cell_m = 1 }
default_ground = "medium_hard"

[ground.medium_hard]
kappa = 0.05

[blocks]
file = "blocks.csv"
roughness = 0.3

[release]
runs = "runs.csv"
rocks = 4
seed = 11

[solver]
max_time_s = 10
impact_substeps = 1
contact_solve = "gauss_seidel"
)";
  return io::LoadScene((dir / "scene.toml").string());
}

// `release` with the round block's roughness set, its shape remade.
ensemble::ReleaseSpec WithRoughness(ensemble::ReleaseSpec release, double roughness) {
  ensemble::Block& round = release.blocks[0];
  round.knobs.roughness = roughness;
  round.shape = std::make_shared<const RockShape>(round.make(round.knobs));
  return release;
}

// The runs of one block, with their observations.
struct BlockRuns {
  ensemble::ReleaseSpec release;
  fieldobs::ObservationSet observations;
};
BlockRuns RunsOf(const ensemble::ReleaseSpec& release, const fieldobs::ObservationSet& all,
                 const std::string& block) {
  BlockRuns out{release, {}};
  out.release.runs.clear();
  for (const ensemble::ReleaseRun& r : release.runs)
    if (release.blocks[static_cast<std::size_t>(r.block)].id == block)
      out.release.runs.push_back(r);
  for (const auto& o : all.scalars)
    for (const ensemble::ReleaseRun& r : out.release.runs)
      if (o.run == r.id) out.observations.scalars.push_back(o);
  return out;
}

// The data's standard error of a parameter from the runs of the block that measures it, as
// testing::MeasuredDataError: within-run sd at the truth, slope of the runs' mean by least squares
// over truth - delta, truth, truth + delta (the other parameter at its truth).
testing::DataError DataErrorOf(const BlockRuns& runs,
                               const std::function<testing::Moments(double)>& at, double truth,
                               double delta) {
  testing::DataError e;
  double sum_xy = 0, sum_xx = 0;
  for (double x : {-delta, delta}) {
    sum_xy += x * at(truth + x).mean;
    sum_xx += x * x;
  }
  e.sd = at(truth).sd;
  e.slope = sum_xy / sum_xx;  // the centre point adds nothing to a symmetric least-squares slope
  e.se = e.sd / (std::abs(e.slope) * std::sqrt(double(runs.observations.scalars.size()))) *
         std::sqrt(1 + 1.0 / double(runs.release.rocks_per_release));
  return e;
}

// Ceres from mu_min 0.8 and roughness 0.05 through the calibration call, the covariance at the
// optimum with the step chosen there (as talus calibrate does): both parameters land within 3 of
// the fits' measured spread over draws (plus the optimiser's tolerance) of the truth, the start
// does not, and each stated 95 % interval (fitted +- 1.96 standard errors) holds the truth, with a
// standard error that neither understates that spread by more than a factor 2 nor exceeds it 3
// times over. The fitted blocks carry the roughness, the fitted table mu_min.
// The bands are the fits' spread, not the data's standard error (printed: 0.0072 for mu_min, 0.044
// for the roughness), because a fit of one draw also carries the model's own random numbers and
// the optimiser's stop on a rough objective: over six draws of the observations (release seeds
// 12345 and 100-104) the fits spread by sd 0.034 / 0.036 in mu_min and 0.018 / 0.030 in roughness
// under Gauss-Seidel / the block on stall (bench/README.md, "A block solve for stalled pairs"),
// five times the data's in mu_min. Bands of 3 data standard errors held for the draw of 12345 only
// by chance: the free rotation's written-out Newton iteration (the same root to 1e-15 relative)
// moved this fit from 0.495 to 0.546, within the spread (bench/README.md, "Free rotation written
// out"). Measured then: fitted 0.546 and 0.283, stated standard errors 0.027 and 0.036, at the
// step the rule chose, 0.25 of each range (noise-dominated).
constexpr double kMuFitSpread = 0.036, kRoughnessFitSpread = 0.030;
TEST(ShapeRecovery, CeresRecoversARoughnessAndMuMinTogether) {
  const io::SceneFile file = LoadTwoBlockScene();
  const Scene scene = testing::AsCalibrationRuns(file.scene);
  Scene truth_scene = scene;
  testing::SetMediumHardMuMin(truth_scene, kTruthMu);
  const ensemble::ReleaseSpec truth_release = WithRoughness(file.release, kTruthRoughness);
  const fieldobs::ObservationSet observations =
      testing::DrawObservations(truth_scene, truth_release, fieldobs::Quantity::kRunout);
  ASSERT_EQ(observations.scalars.size(), std::size_t(kRuns));

  const BlockRuns slab = RunsOf(truth_release, observations, "slab");
  const BlockRuns round = RunsOf(truth_release, observations, "round");
  const testing::DataError mu_error = DataErrorOf(
      slab,
      [&](double mu) {
        Scene s = scene;
        testing::SetMediumHardMuMin(s, mu);
        return testing::QuantityMoments(s, slab.release, slab.observations);
      },
      kTruthMu, 0.05);
  const testing::DataError roughness_error = DataErrorOf(
      round,
      [&](double roughness) {
        return testing::QuantityMoments(truth_scene, WithRoughness(round.release, roughness),
                                        round.observations);
      },
      kTruthRoughness, 0.1);
  std::printf(
      "data: mu_min sd %.4g m, slope %.4g m, se %.4f; roughness sd %.4g m, slope %.4g m, "
      "se %.4f\n",
      mu_error.sd, mu_error.slope, mu_error.se, roughness_error.sd, roughness_error.slope,
      roughness_error.se);

  ParameterSpec mu = testing::Spec("medium_hard", GroundField::kMuMin, kMuLower, kMuUpper);
  ParameterSpec roughness;
  roughness.block = "round";
  roughness.shape_field = ShapeField::kRoughness;
  roughness.lower = 0;
  roughness.upper = kRoughnessUpper;
  ObjectiveOptions objective;
  objective.threads = 2;
  const CalibrationProblem problem(file.scene, file.release, observations, {mu, roughness},
                                   objective);
  CalibrationOptions options;
  options.optimizer.algorithm = "ceres";
  options.optimizer.max_evaluations = 40;
  options.optimizer.start = Eigen::Vector2d((kStartMu - kMuLower) / (kMuUpper - kMuLower),
                                            kStartRoughness / kRoughnessUpper);
  options.roughness = false;
  options.uncertainty_options.fd_step = 0;  // chosen at the optimum, as talus calibrate does
  options.on_progress = [](const std::string& text) { std::printf("%s", text.c_str()); };
  const CalibrationSummary run = Calibrate(problem, options);
  ASSERT_TRUE(run.uncertainty && run.uncertainty->computed);

  const double tolerances[] = {
      3 * kMuFitSpread + options.optimizer.xtol_abs * (kMuUpper - kMuLower),
      3 * kRoughnessFitSpread + options.optimizer.xtol_abs * kRoughnessUpper};
  const double truths[] = {kTruthMu, kTruthRoughness}, starts[] = {kStartMu, kStartRoughness};
  const double data_se[] = {mu_error.se, roughness_error.se};
  const double spreads[] = {kMuFitSpread, kRoughnessFitSpread};
  for (int k = 0; k < 2; ++k) {
    const double fitted = run.fit.best.values[k];
    const double se = run.uncertainty->standard_error[k];
    std::printf(
        "%s: fitted %.4f (truth %.2f, tolerance %.4f), stated standard error %.4f "
        "(fits' spread %.4f, data's standard error %.4f)\n",
        run.uncertainty->names[static_cast<std::size_t>(k)].c_str(), fitted, truths[k],
        tolerances[k], se, spreads[k], data_se[k]);
    EXPECT_GT(std::abs(starts[k] - truths[k]), tolerances[k]);
    EXPECT_NEAR(fitted, truths[k], tolerances[k]);
    EXPECT_NEAR(fitted, truths[k], 1.96 * se);
    EXPECT_LT(se, 3 * spreads[k]);
    EXPECT_GT(se, spreads[k] / 2);
  }
  EXPECT_EQ(run.uncertainty->names[1], "blocks.round.roughness");
  ASSERT_EQ(run.fitted_blocks.size(), 2u);
  EXPECT_EQ(run.fitted_blocks[0].knobs.roughness, run.fit.best.values[1]);
  EXPECT_TRUE(std::isnan(run.fitted_blocks[1].knobs.roughness));  // the slab has none
  EXPECT_EQ(run.fitted.params(run.fitted.IndexOfName("medium_hard")).mu_min,
            run.fit.best.values[0]);
}

}  // namespace
}  // namespace talus::calibration
