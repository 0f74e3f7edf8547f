// Contact episodes on a plane where the answer is known in closed form.

#include "solver/episodes.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scenes/scenes.hpp"
#include "solver/shapes.hpp"

namespace talus {
namespace {

constexpr double kG = 9.81;

Scene Flat(double mu, double restitution = 0) {
  Scene scene =
      scenes::Incline(0, MakeRockShape(MakeBox(1, 1, 0.5), 2700), GroundParams{mu, mu, 150, 2, 0});
  scene.options.normal_restitution = scene.options.tangential_restitution = restitution;
  return scene;
}

std::vector<ContactEpisode> RunRecording(const Scene& scene, const RockState& start,
                                         RockResult* result) {
  EpisodeRecorder recorder(scene.terrain);
  recorder.Begin(start);
  SimulationWorkspace ws;
  *result = SimulateRock(scene, start, ws, &recorder);
  return recorder.Finish();
}

TEST(Episodes, ABlockSlidingToRestIsOneEpisodeWhoseScarIsTheSlidingDistance) {
  // A 1 x 1 x 0.5 m box resting flat on ground with mu = 0.5 (constant), pushed at v0 = 3 m/s:
  // it slides v0^2 / (2 mu g) = 0.9174 m in v0 / (mu g) = 0.6116 s and rests. The scar grows by
  // |v_E| dt while loaded, so it equals the sliding distance up to one step's travel (v0 dt =
  // 6 mm); the horizontal path agrees likewise. The tolerance is 1 % of the distance.
  const Scene scene = Flat(0.5);
  RockState start;
  start.position_m = {50, 0, 0.25};
  start.velocity_m_s = {3, 0, 0};
  RockResult result;
  const std::vector<ContactEpisode> episodes = RunRecording(scene, start, &result);
  ASSERT_EQ(result.end, EndReason::kRest);
  ASSERT_EQ(episodes.size(), 1u);
  const ContactEpisode& e = episodes[0];
  const double distance = 9.0 / (2 * 0.5 * kG);
  EXPECT_NEAR(result.runout_m, distance, 0.01 * distance);
  EXPECT_NEAR(e.max_scar_m, distance, 0.01 * distance);
  EXPECT_NEAR(e.path_length_m, distance, 0.01 * distance);
  EXPECT_NEAR(e.velocity_in_m_s.x(), 3.0, 1e-12);
  EXPECT_LT(e.velocity_out_m_s.norm(), scene.options.rest_speed_m_s);
  EXPECT_TRUE(e.loaded);
  EXPECT_EQ(e.ground, scene.ground.IndexOfName("test"));
  EXPECT_NEAR(e.start_time_s, 0.0, 1e-12);
  EXPECT_NEAR(e.end_time_s, result.travel_time_s, 1e-12);  // it ends at rest, still in contact
}

TEST(Episodes, BouncesWithRestitutionAreSeparateEpisodesWithTheFallSpeeds) {
  // Newton restitution eps = 0.5, dropped flat from h0 = 1 m (bottom face 1 m above ground):
  // impact k arrives at v0 eps^(k-1), v0 = sqrt(2 g h0), and leaves at eps times that; the flight
  // after it lasts 2 eps^k v0 / g: 0.452, 0.226, 0.113, 0.056, 0.028 s. Flights of at least
  // min_flight_s = 0.05 s separate episodes, so impacts 1-4 are episodes of their own and the
  // fifth merges with what follows: 5 episodes. The "in" and "out" states are those of step ends,
  // not of the impact instant, so each speed is checked to one step's gravity, g dt = 0.0196 m/s:
  // the first arrival against v0, each departure against eps times its arrival (Newton's law), and
  // each arrival against the previous departure (a symmetric flight).
  // The count is that of the converged contact solve (1e-7 m/s): at the default 1e-3 m/s the
  // same drop gives 4 episodes instead of 5.
  Scene scene = Flat(0.5, 0.5);
  scene.options.tolerance_m_s = 1e-7;
  RockState start;
  start.position_m = {50, 0, 1.25};
  RockResult result;
  const std::vector<ContactEpisode> episodes = RunRecording(scene, start, &result);
  ASSERT_EQ(episodes.size(), 5u);
  const double g_dt = kG * scene.options.dt_s;
  EXPECT_NEAR(-episodes[0].velocity_in_m_s.z(), std::sqrt(2 * kG * 1.0), g_dt);
  for (std::size_t k = 0; k < 4; ++k) {
    const double in = -episodes[k].velocity_in_m_s.z();
    EXPECT_NEAR(episodes[k].velocity_out_m_s.z(), 0.5 * in, g_dt) << "episode " << k;
    if (k > 0) {
      EXPECT_NEAR(in, episodes[k - 1].velocity_out_m_s.z(), g_dt) << "episode " << k;
    }
    EXPECT_LT(episodes[k].duration_s(), 0.01) << "an impact lasts a step or two";
  }
  // Between episodes the flights are those of the closed form (to two steps).
  for (std::size_t k = 0; k + 1 < 4; ++k) {
    const double flight = 2 * std::pow(0.5, double(k + 1)) * std::sqrt(2 * 1.0 / kG);
    EXPECT_NEAR(episodes[k + 1].start_time_s - episodes[k].end_time_s, flight, 0.005);
  }
}

TEST(Episodes, AFlightLongerThanTheThresholdSplitsShorterOnesDoNot) {
  // The same bounces with min_flight_s = 0.2 s: only the flights of 0.452 and 0.226 s separate,
  // so 3 episodes.
  const Scene scene = Flat(0.5, 0.5);
  RockState start;
  start.position_m = {50, 0, 1.25};
  EpisodeRecorder recorder(scene.terrain, EpisodeOptions{0.2});
  recorder.Begin(start);
  SimulationWorkspace ws;
  SimulateRock(scene, start, ws, &recorder);
  EXPECT_EQ(recorder.Finish().size(), 3u);
}

TEST(Episodes, ARockThatNeverTouchesHasNone) {
  const Scene scene = Flat(0.5);
  RockState start;
  start.position_m = {150, 0, 50};
  start.velocity_m_s = {100, 0, 0};  // leaves the DEM in flight
  RockResult result;
  EXPECT_TRUE(RunRecording(scene, start, &result).empty());
  EXPECT_EQ(result.end, EndReason::kLeftDomain);
}

}  // namespace
}  // namespace talus
