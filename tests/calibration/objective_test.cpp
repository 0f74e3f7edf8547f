// The calibration objective: common random numbers, no state carried between evaluations,
// thread-count independence, the contact-solve tolerance, infeasible vectors, residuals and the
// climatology scale.

#include "calibration/objective.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "calibration/holdout.hpp"
#include "common/error.hpp"
#include "fieldobs/validation.hpp"
#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

ParameterSpec MuMin(double lower = 0.1, double upper = 0.9) {
  return testing::Spec("medium_hard", GroundField::kMuMin, lower, upper);
}

ObjectiveOptions Threads(int threads) {
  ObjectiveOptions o;
  o.threads = threads;
  return o;
}

const testing::SyntheticRunouts& Problem() {
  static const testing::SyntheticRunouts problem(20, 8, 0.5);
  return problem;
}

// The mean run-out score of `scene` run directly with `ground` and the contact-solve tolerance
// `tolerance_m_s`.
double DirectRunoutScore(const Scene& scene, const GroundTable& ground, double tolerance_m_s) {
  const auto& p = Problem();
  Scene direct = scene;
  direct.ground = ground;
  direct.options.tolerance_m_s = tolerance_m_s;
  fieldobs::EnsembleSamples samples(p.release);
  ensemble::EnsembleOptions options;
  options.threads = 2;
  ensemble::RunEnsemble(direct, p.release, options, &samples);
  return fieldobs::Validate(p.observations, samples, nullptr).kinds[0].mean_score;
}

// Scene copies share the DEM: a copy costs reference counts, not the heights.
TEST(Objective, SceneCopiesShareTheTerrain) {
  const Scene copy = Problem().scene;
  EXPECT_TRUE(copy.terrain.SharesHeightsWith(Problem().scene.terrain));
  EXPECT_EQ(&copy.terrain.heights(), &Problem().scene.terrain.heights());
}

// Evaluating u1 between two evaluations of u0 changes nothing (bit for bit), and an evaluation
// equals running the never-edited scene with the same table directly.
TEST(Objective, EditEvaluateRestoreIsBitIdenticalToNeverEditing) {
  const auto& p = Problem();
  const Objective objective(p.scene, p.release, p.observations, {MuMin()}, Threads(2));
  const Eigen::VectorXd u0 = Eigen::VectorXd::Constant(1, 0.3);
  const Evaluation a = objective.Evaluate(u0);
  const Evaluation other = objective.Evaluate(Eigen::VectorXd::Constant(1, 0.9));
  const Evaluation b = objective.Evaluate(u0);
  ASSERT_TRUE(a.feasible);
  EXPECT_NE(a.value, other.value);
  EXPECT_EQ(a.value, b.value);
  EXPECT_EQ(a.residuals, b.residuals);
  EXPECT_EQ(a.kind_scores, b.kind_scores);

  EXPECT_EQ(a.kind_scores[0],
            DirectRunoutScore(p.scene, objective.GroundOf(u0), objective.options().tolerance_m_s));

  // A ground table edited and restored runs exactly as one never edited.
  Scene edited = p.scene;
  const int g = edited.ground.IndexOfName("medium_hard");
  const GroundParams saved = edited.ground.params(g);
  objective.parameters().Apply(Eigen::VectorXd::Constant(1, 0.9), edited.ground, nullptr);
  edited.ground.mutable_params(g) = saved;
  fieldobs::EnsembleSamples restored(p.release), never(p.release);
  ensemble::EnsembleOptions options;
  options.threads = 2;
  ensemble::RunEnsemble(edited, p.release, options, &restored);
  ensemble::RunEnsemble(p.scene, p.release, options, &never);
  EXPECT_EQ(restored.Values(fieldobs::Quantity::kRunout, ""),
            never.Values(fieldobs::Quantity::kRunout, ""));
}

// Every evaluation runs the contact solve at the objective's tolerance (1e-7 m/s unless asked
// otherwise), whatever the scene's: an evaluation of a scene set to 1e-3 m/s equals a direct run
// at 1e-7 m/s bit for bit and differs from one at 1e-3 m/s; asked for 1e-3 m/s, it equals that.
TEST(Objective, RunsEveryEvaluationAtItsOwnTolerance) {
  const auto& p = Problem();
  Scene loose = p.scene;
  loose.options.tolerance_m_s = 1e-3;
  const Objective objective(loose, p.release, p.observations, {MuMin()}, Threads(2));
  EXPECT_EQ(objective.options().tolerance_m_s, 1e-7);
  EXPECT_EQ(objective.scene().options.tolerance_m_s, 1e-7);
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.3);
  const double tight = DirectRunoutScore(loose, objective.GroundOf(u), 1e-7);
  const double at_loose = DirectRunoutScore(loose, objective.GroundOf(u), 1e-3);
  ASSERT_NE(tight, at_loose);  // the tolerance changes this problem's scores
  EXPECT_EQ(objective.Evaluate(u).kind_scores[0], tight);

  ObjectiveOptions options = Threads(2);
  options.tolerance_m_s = 1e-3;
  const Objective asked(p.scene, p.release, p.observations, {MuMin()}, options);
  EXPECT_EQ(asked.Evaluate(u).kind_scores[0], at_loose);
}

// A tolerance outside (0, 1) m/s (or not finite) is refused, naming the option.
TEST(Objective, RejectsAToleranceOutsideZeroToOne) {
  const auto& p = Problem();
  for (double tolerance : {0.0, -1e-7, 1.0, std::nan(""), HUGE_VAL}) {
    ObjectiveOptions options = Threads(2);
    options.tolerance_m_s = tolerance;
    try {
      const Objective objective(p.scene, p.release, p.observations, {MuMin()}, options);
      ADD_FAILURE() << "accepted tolerance_m_s = " << tolerance;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("tolerance_m_s"), std::string::npos) << e.what();
    }
  }
}

TEST(Objective, IsTheSameForOneAndTwoThreads) {
  const auto& p = Problem();
  const Objective one(p.scene, p.release, p.observations, {MuMin()}, Threads(1));
  const Objective two(p.scene, p.release, p.observations, {MuMin()}, Threads(2));
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(1, 0.45);
  const Evaluation a = one.Evaluate(u), b = two.Evaluate(u);
  EXPECT_EQ(a.value, b.value);
  EXPECT_EQ(a.residuals, b.residuals);
}

// The normalised runout term is the mean CRPS over the climatology's mean CRPS, the same number
// fieldobs::Validate reports; the residuals' squares add up to the data term (to round-off,
// 1e-12 relative: a sum of 20 squares of square roots).
TEST(Objective, ScaleIsTheClimatologyScoreAndResidualsSquareToTheValue) {
  const auto& p = Problem();
  ObjectiveOptions options = Threads(2);
  const Objective objective(p.scene, p.release, p.observations, {MuMin()}, options);
  const Evaluation e = objective.Evaluate(Eigen::VectorXd::Constant(1, 0.5));
  fieldobs::EnsembleSamples samples(p.release);
  ensemble::EnsembleOptions run;
  run.threads = 2;
  Scene scene = objective.scene();  // the objective's contact-solve tolerance
  scene.ground = objective.GroundOf(e.u);
  ensemble::RunEnsemble(scene, p.release, run, &samples);
  const fieldobs::ValidationReport report = fieldobs::Validate(p.observations, samples, nullptr);
  EXPECT_NEAR(objective.kind_scales()[0], report.kinds[0].mean_climatology_score,
              1e-12 * report.kinds[0].mean_climatology_score);
  EXPECT_NEAR(e.data, 1 - report.kinds[0].skill_vs_climatology, 1e-12);
  EXPECT_NEAR(e.residuals.squaredNorm(), e.value, 1e-12 * e.value);
  EXPECT_EQ(e.rocks, 20 * 8);
}

// mu_min above mu_max: no rock runs, the value is the stated finite penalty.
TEST(Objective, InfeasibleVectorsRunNoRockAndGetTheStatedPenalty) {
  const auto& p = Problem();
  ParameterSpec mu_max = MuMin(0.3, 1.5);
  mu_max.field = GroundField::kMuMax;
  const Objective objective(p.scene, p.release, p.observations, {MuMin(0.1, 0.9), mu_max},
                            Threads(2));
  const Evaluation e = objective.Evaluate(Eigen::Vector2d(1.0, 0.0));  // 0.9 > 0.3
  EXPECT_FALSE(e.feasible);
  EXPECT_EQ(e.rocks, 0);
  EXPECT_DOUBLE_EQ(e.value, 1e3 * (1 + 0.6));
  EXPECT_EQ(e.infeasible, "medium_hard: mu_max = 0.3 violates mu_min <= mu_max < infinity");
}

// Trajectory-segment and zone observations are scored in calibration as in validation: the
// evaluation records what they need (fieldobs::AddRecordersFor), in the fit and in the held-out
// scores alike. Without the recorders no rock gives these values and the vector is infeasible.
TEST(Objective, SegmentAndZoneObservationsAreScored) {
  const auto& p = Problem();
  fieldobs::ObservationSet observations;
  fieldobs::Zone line;
  line.id = "profile";
  line.points = {{6.0, -40.0}, {6.0, 40.0}};  // across the slope, 4 m below the starts (x = 2)
  observations.zones.push_back(line);
  for (const ensemble::ReleaseRun& run : p.release.runs) {
    const double spread = 0.1 * static_cast<double>(observations.scalars.size());
    fieldobs::ScalarObservation segment{fieldobs::Quantity::kSegmentMaxSpeed, run.id, 4.0 + spread,
                                        run.id};
    segment.window_s = 1.0;
    observations.scalars.push_back(segment);
    fieldobs::ScalarObservation zone{fieldobs::Quantity::kZoneSpeed, run.id, 5.0 + spread, run.id};
    zone.zone = 0;
    observations.scalars.push_back(zone);
  }
  const Objective objective(p.scene, p.release, observations, {MuMin()}, Threads(2));
  const Evaluation e = objective.Evaluate(Eigen::VectorXd::Constant(1, 0.5));
  ASSERT_TRUE(e.feasible) << e.infeasible;
  ASSERT_EQ(objective.kinds().size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) EXPECT_EQ(e.kind_scored[k], 20) << objective.kinds()[k];

  const RunSubset subset = SelectRuns(p.release, observations, {"run0", "run1"}, false);
  const HeldOutScores held =
      ScoreRuns(p.scene, subset, objective.GroundOf(e.u), nullptr, 2, false, nullptr);
  ASSERT_EQ(held.kinds.size(), 2u);
  for (const HeldOutKind& kind : held.kinds) EXPECT_EQ(kind.scored, 2) << kind.kind;
}

TEST(Objective, WeightOfAKindWithoutObservationsIsAnError) {
  const auto& p = Problem();
  ObjectiveOptions options;
  options.weights["scar_length"] = 1;
  try {
    const Objective objective(p.scene, p.release, p.observations, {MuMin()}, options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "weights.scar_length: no observation of kind 'scar_length' (the observations "
                 "are of: runout)");
  }
}

}  // namespace
}  // namespace talus::calibration
