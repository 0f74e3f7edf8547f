#include "ensemble/recorders.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "fixtures.hpp"

namespace talus::ensemble {
namespace {

constexpr double kDt = 0.002;

// A rock whose principal frame differs from its input axes, and its outcome at t = 0.
struct Rock {
  std::shared_ptr<const RockShape> shape =
      std::make_shared<RockShape>(MakeRockShape(MakeBox(0.2, 0.5, 0.9), 2700));
  RockOutcome outcome;
  explicit Rock(long rock) {
    outcome.rock = rock;
    outcome.shape = shape;
    outcome.start.position_m = {1, 2, 3};
    outcome.start.orientation =
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
    outcome.start.angular_velocity_rad_s = {0, 0, 1};
  }
};

// Feeds `steps` steps of dt to the recorder: the state moves along x at 1 m/s; steps with an
// index in `contact_steps` report a contact.
void Feed(RockRecorder& recorder, Rock& rock, int steps,
          const std::vector<int>& contact_steps = {}) {
  recorder.Begin(rock.outcome);
  RockState state = rock.outcome.start;
  for (int k = 1; k <= steps; ++k) {
    state.time_s = k * kDt;
    state.position_m.x() = 1 + state.time_s;
    state.scar_m = 0.001 * k;
    StepReport step;
    for (int c : contact_steps) step.contacts += c == k;
    recorder.OnStep(state, step, TerrainSample{});
  }
  recorder.Finish(rock.outcome);
}

TEST(TrajectoryRecorder, SamplesTheStartEveryIntervalAndTheEnd) {
  auto recorder = MakeTrajectoryRecorder(0.01, kDt, [](long) { return true; });
  Rock rock(0);
  Feed(*recorder, rock, 26);  // ends at 0.052 s, between samples
  const std::vector<TrajectorySample>& t = rock.outcome.trajectory;
  ASSERT_EQ(t.size(), 7u);  // 0, 0.01, ..., 0.05, 0.052
  for (int k = 0; k <= 5; ++k) EXPECT_NEAR(t[static_cast<std::size_t>(k)].t_s, 0.01 * k, 1e-12);
  EXPECT_NEAR(t.back().t_s, 0.052, 1e-12);
  EXPECT_NEAR(t.back().position_m.x(), 1.052, 1e-12);
  EXPECT_NEAR(t.back().scar_m, 0.026, 1e-12);
  EXPECT_EQ(t[0].position_m, rock.outcome.start.position_m);
}

TEST(TrajectoryRecorder, AnEndOnASampleIsNotRecordedTwice) {
  auto recorder = MakeTrajectoryRecorder(0.01, kDt, [](long) { return true; });
  Rock rock(0);
  Feed(*recorder, rock, 25);  // ends at 0.05 s, a sample time
  ASSERT_EQ(rock.outcome.trajectory.size(), 6u);
  EXPECT_NEAR(rock.outcome.trajectory.back().t_s, 0.05, 1e-12);
}

TEST(TrajectoryRecorder, SamplesAreInTheUsersFrames) {
  auto recorder = MakeTrajectoryRecorder(0.01, kDt, [](long) { return true; });
  Rock rock(0);
  Feed(*recorder, rock, 5, {5});
  const TrajectorySample& s = rock.outcome.trajectory.at(0);
  // The quaternion rotates the shape as given; the angular velocity is in the world frame.
  const Eigen::Quaterniond& principal = rock.outcome.start.orientation;
  EXPECT_NEAR(std::abs(s.orientation.dot(rock.shape->ShapeOrientation(principal))), 1, 1e-12);
  EXPECT_FALSE(std::abs(s.orientation.dot(principal)) > 1 - 1e-6);  // the frames do differ
  EXPECT_TRUE(s.angular_velocity_rad_s.isApprox(principal * Eigen::Vector3d(0, 0, 1), 1e-12));
  EXPECT_FALSE(s.contact);
  EXPECT_TRUE(rock.outcome.trajectory.back().contact);  // the end step had a contact
}

TEST(TrajectoryRecorder, RecordsOnlyTheRocksItIsAskedForAndForgetsTheLastRock) {
  auto recorder = MakeTrajectoryRecorder(0.01, kDt, [](long rock) { return rock % 2 == 1; });
  Rock wanted(1), unwanted(2), again(3);
  Feed(*recorder, wanted, 30);
  Feed(*recorder, unwanted, 30);
  Feed(*recorder, again, 10);
  EXPECT_EQ(wanted.outcome.trajectory.size(), 7u);  // 0 .. 0.06
  EXPECT_TRUE(unwanted.outcome.trajectory.empty());
  ASSERT_EQ(again.outcome.trajectory.size(), 3u);  // 0, 0.01, 0.02: nothing of rock 1
  EXPECT_NEAR(again.outcome.trajectory.back().t_s, 0.02, 1e-12);
}

TEST(TrajectoryRecorder, ARockThatEndsAtOnceHasItsStartOnly) {
  auto recorder = MakeTrajectoryRecorder(0.01, kDt, [](long) { return true; });
  Rock rock(0);
  Feed(*recorder, rock, 0);
  ASSERT_EQ(rock.outcome.trajectory.size(), 1u);
  EXPECT_EQ(rock.outcome.trajectory[0].t_s, 0);
}

TEST(EpisodeRecorder, HandsTheEpisodesOfARockOverThroughTheOutcome) {
  const Scene scene = testing::SmallPlane(0, 0, 20, 10);
  auto recorder = MakeEpisodeRecorder(scene.terrain, EpisodeOptions{});
  Rock rock(0);
  rock.outcome.start.position_m = {5, 0, 0.2};
  rock.outcome.start.velocity_m_s = {1, 0, 0};
  Feed(*recorder, rock, 100, {10, 11, 12, 13, 14});  // one stretch of contact, then 0.17 s flight
  ASSERT_EQ(rock.outcome.episodes.size(), 1u);
  EXPECT_EQ(rock.outcome.episodes[0].contact_steps, 5);
  EXPECT_NEAR(rock.outcome.episodes[0].end_time_s, 14 * kDt, 1e-12);
  Rock next(1);
  Feed(*recorder, next, 20);
  EXPECT_TRUE(next.outcome.episodes.empty());  // nothing carried over from rock 0
}

}  // namespace
}  // namespace talus::ensemble
