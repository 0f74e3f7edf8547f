#include "ensemble/runner.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "fixtures.hpp"

namespace talus::ensemble {
namespace {

class Collect : public RockSink {
 public:
  void OnRock(const RockOutcome& outcome) override { rocks.push_back(outcome); }
  std::vector<RockOutcome> rocks;
};

// Bit-identical, as the thread-count contract says: -0 and 0 differ, a NaN equals itself.
template <class T>
bool SameBits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;  // NOLINT(bugprone-suspicious-memory-comparison)
}

// Runs with their own blocks, start states and a shape of their own per rock (from a seeded
// generator): bit-identical for 1 and 2 threads, episodes included, and each rock runs with the
// shape its (seed, rock) gives.
TEST(RunEnsemble, RunsWithShapesPerRockAreBitIdenticalForAnyThreadCount) {
  Scene scene = testing::SmallPlane(35, 25, 10);
  scene.options.max_time_s = 4;
  ReleaseSpec release;
  release.blocks.push_back(
      {"slab", std::make_shared<const RockShape>(MakeRockShape(MakeBox(0.6, 0.4, 0.15), 2700)),
       {}, {}});
  ReleaseRun a;
  a.id = "a";
  a.xy_m = {3, 0};
  a.velocity_m_s = {2, 0, 0};
  ReleaseRun b = a;
  b.id = "b";
  b.xy_m = {4, 2};
  b.block = 0;
  b.z_m = 25;  // well above ground: falls first
  release.runs = {a, b};
  release.rocks_per_release = 3;
  release.shape_per_rock = [](const Block* block, std::uint64_t seed) {
    const double c = 0.1 + double(seed % 1000) / 5000.0;  // 0.1 .. 0.3 m
    return MakeRockShape(MakeBox(block ? 0.6 : 0.4, 0.4, c), 2700);
  };
  std::string why;
  ASSERT_TRUE(release.IsValid(&why)) << why;
  EnsembleOptions options;
  options.episodes = true;
  std::vector<Collect> runs(2);
  for (int threads = 1; threads <= 2; ++threads) {
    options.threads = threads;
    RunEnsemble(scene, release, options, &runs[threads - 1]);
  }
  ASSERT_EQ(runs[1].rocks.size(), 6u);
  for (std::size_t r = 0; r < 6; ++r) {
    const RockOutcome& x = runs[0].rocks[r];
    const RockOutcome& y = runs[1].rocks[r];
    EXPECT_EQ(x.release, static_cast<int>(r / 3));
    EXPECT_TRUE(SameBits(x.result.final_state.position_m, y.result.final_state.position_m));
    EXPECT_TRUE(SameBits(x.shape->mass_kg, y.shape->mass_kg));
    const RockShape expected =
        release.shape_per_rock(x.release == 1 ? &release.blocks[0] : nullptr,
                               RockShapeSeed(release.seed, x.rock));
    EXPECT_EQ(x.shape->mass_kg, expected.mass_kg);
    ASSERT_EQ(x.episodes.size(), y.episodes.size());
    EXPECT_FALSE(x.episodes.empty());
    for (std::size_t e = 0; e < x.episodes.size(); ++e)
      EXPECT_TRUE(SameBits(x.episodes[e].velocity_out_m_s, y.episodes[e].velocity_out_m_s));
  }
  // Run b starts at its z_m (no raise needed) with its velocity; run a on the ground.
  EXPECT_EQ(runs[0].rocks[3].start.position_m.z(), 25);
  EXPECT_EQ(runs[0].rocks[0].start.velocity_m_s, Eigen::Vector3d(2, 0, 0));
  // Different seeds give different shapes within a run.
  EXPECT_NE(runs[0].rocks[0].shape->mass_kg, runs[0].rocks[1].shape->mass_kg);
}

// Bit-identical results for 1, 2 and 3 threads: rock results, trajectories and every raster.
TEST(RunEnsemble, BitIdenticalForAnyThreadCount) {
  Scene scene = testing::SmallPlane(35, 25, 10);
  scene.options.max_time_s = 4;
  ReleaseSpec release = testing::PointRelease({{3, 0}, {4, 2}}, 5);
  EnsembleOptions options;
  options.trajectories = true;
  options.trajectory_interval_s = 0.05;
  options.rasters = {scene.terrain.heights().grid, true, true, true, true, true, true};

  std::vector<Collect> runs(3);
  std::vector<EnsembleReport> reports;
  for (int threads = 1; threads <= 3; ++threads) {
    options.threads = threads;
    reports.push_back(RunEnsemble(scene, release, options, &runs[threads - 1]));
    EXPECT_EQ(reports.back().threads, threads);
  }
  for (int k = 1; k < 3; ++k) {
    ASSERT_EQ(runs[k].rocks.size(), 10u);
    for (std::size_t r = 0; r < 10; ++r) {
      const RockOutcome& a = runs[0].rocks[r];
      const RockOutcome& b = runs[k].rocks[r];
      EXPECT_EQ(b.rock, static_cast<long>(r));
      EXPECT_EQ(a.result.end, b.result.end);
      EXPECT_EQ(a.result.steps, b.result.steps);
      EXPECT_TRUE(SameBits(a.result.final_state.position_m, b.result.final_state.position_m));
      EXPECT_TRUE(SameBits(a.result.max_kinetic_energy_j, b.result.max_kinetic_energy_j));
      ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
      for (std::size_t s = 0; s < a.trajectory.size(); ++s)
        EXPECT_TRUE(SameBits(a.trajectory[s].position_m, b.trajectory[s].position_m));
    }
    ASSERT_EQ(reports[0].rasters.size(), reports[k].rasters.size());
    for (std::size_t l = 0; l < reports[0].rasters.size(); ++l) {
      const auto& a = reports[0].rasters[l].values;
      const auto& b = reports[k].rasters[l].values;
      ASSERT_EQ(a.size(), b.size());
      EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0)
          << reports[0].rasters[l].name;
    }
  }
  EXPECT_EQ(reports[0].rocks, 10);
  EXPECT_EQ(reports[0].rasters.size(), 12u);  // 3 x 3 statistics, passages, deposits, reach
}

// Barriers act inside each rock's run, so their events and the rocks they stop are bit-identical
// for 1, 2 and 3 threads too; the stopped rocks are counted by their ending and as deposits.
TEST(RunEnsemble, BarriersAreBitIdenticalForAnyThreadCount) {
  Scene scene = testing::SmallPlane(35, 25, 10);
  scene.options.max_time_s = 4;
  scene.barriers = {{"net", BarrierType::kFlexibleNet, {{5, -8}, {5, 8}}, 0.4, 120},
                    {"wall", BarrierType::kRigidWall, {{6, -8}, {6, 8}}, 1, 50}};
  ReleaseSpec release = testing::PointRelease({{3, 0}, {4, 2}}, 5);
  EnsembleOptions options;
  options.rasters = {scene.terrain.heights().grid, false, false, false, false, true, false};
  std::vector<Collect> runs(3);
  std::vector<EnsembleReport> reports;
  for (int threads = 1; threads <= 3; ++threads) {
    options.threads = threads;
    reports.push_back(RunEnsemble(scene, release, options, &runs[threads - 1]));
  }
  long events = 0;
  for (const RockOutcome& a : runs[0].rocks) events += long(a.result.barrier_events.size());
  EXPECT_GT(events, 3);
  EXPECT_GT(reports[0].count(EndReason::kBarrier), 0);
  float deposits = 0;
  for (float d : reports[0].rasters.front().values) deposits += d > 0 ? d : 0;
  EXPECT_EQ(deposits,
            float(reports[0].count(EndReason::kRest) + reports[0].count(EndReason::kBarrier)));
  for (int k = 1; k < 3; ++k) {
    EXPECT_EQ(reports[k].by_end, reports[0].by_end);
    for (std::size_t r = 0; r < 10; ++r) {
      const RockResult& a = runs[0].rocks[r].result;
      const RockResult& b = runs[k].rocks[r].result;
      EXPECT_EQ(a.end, b.end);
      EXPECT_TRUE(SameBits(a.final_state.position_m, b.final_state.position_m));
      ASSERT_EQ(a.barrier_events.size(), b.barrier_events.size());
      for (std::size_t e = 0; e < a.barrier_events.size(); ++e) {
        EXPECT_EQ(a.barrier_events[e].outcome, b.barrier_events[e].outcome);
        EXPECT_TRUE(
            SameBits(a.barrier_events[e].energy_after_J, b.barrier_events[e].energy_after_J));
        EXPECT_TRUE(SameBits(a.barrier_events[e].position_m, b.barrier_events[e].position_m));
      }
    }
  }
}

// Trajectories speak the user's conventions: the quaternion rotates the shape as given, the
// angular velocity is in the world frame, and samples come every interval.
TEST(RunEnsemble, TrajectoriesUseTheShapeAsGivenAndTheWorldFrame) {
  Scene scene = testing::SmallPlane(0, 0, 20, 10);
  scene.rock = MakeRockShape(MakeBox(0.2, 0.5, 0.9), 2700);  // principal frame != input axes
  ReleaseSpec release = testing::PointRelease({{5, 0}}, 1);
  release.height_m = 3;
  const Eigen::Quaterniond user(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -1, 2).normalized()));
  release.orientation = user;
  release.angular_velocity_rad_s = Eigen::Vector3d(0.5, -1, 2);
  EnsembleOptions options;
  options.trajectories = true;
  options.trajectory_interval_s = 0.1;
  Collect sink;
  RunEnsemble(scene, release, options, &sink);
  const auto& t = sink.rocks.at(0).trajectory;
  ASSERT_GT(t.size(), 5u);
  EXPECT_NEAR(std::abs(t[0].orientation.dot(user)), 1.0, 1e-12);
  EXPECT_TRUE(t[0].angular_velocity_rad_s.isApprox(release.angular_velocity_rad_s, 1e-12));
  // In flight the world-frame angular momentum is conserved (to the scheme's 1e-7 here; a frame
  // mix-up would be off by order one): check it at the next sample (0.1 s,
  // before the 3 m drop hits the ground).
  const auto momentum = [&](const TrajectorySample& s) {
    const Eigen::Matrix3d to_world =
        (s.orientation * scene.rock.principal_to_input).toRotationMatrix();
    const Eigen::Vector3d body = to_world.transpose() * s.angular_velocity_rad_s;
    return Eigen::Vector3d(to_world * scene.rock.inertia_kg_m2.cwiseProduct(body));
  };
  EXPECT_TRUE(momentum(t[1]).isApprox(momentum(t[0]), 1e-5))
      << momentum(t[0]).transpose() << " vs " << momentum(t[1]).transpose();
  EXPECT_NEAR(t[1].t_s, 0.1, 1e-9);
  EXPECT_NEAR(t[2].t_s - t[1].t_s, 0.1, 1e-9);
}

TEST(RunEnsemble, NoRasterRequestedMeansNoRasters) {
  const Scene scene = testing::SmallPlane(0, 0, 10, 10);
  ReleaseSpec release = testing::PointRelease({{5, 0}}, 2);
  release.height_m = 0.2;
  release.orientation = Eigen::Quaterniond::Identity();
  const EnsembleReport report = RunEnsemble(scene, release, EnsembleOptions{});
  EXPECT_TRUE(report.rasters.empty());
  EXPECT_EQ(report.count(EndReason::kRest), 2);
}

TEST(RunEnsemble, SinkErrorsStopTheRun) {
  const Scene scene = testing::SmallPlane(0, 0, 10, 10);
  ReleaseSpec release = testing::PointRelease({{5, 0}}, 50);
  release.height_m = 0.2;
  release.orientation = Eigen::Quaterniond::Identity();
  struct Throwing : RockSink {
    void OnRock(const RockOutcome&) override { throw std::runtime_error("disk full"); }
  } sink;
  EnsembleOptions options;
  options.threads = 2;
  EXPECT_THROW(RunEnsemble(scene, release, options, &sink), std::runtime_error);
}

TEST(RunEnsemble, RaisedStartsAreCounted) {
  const Scene scene = testing::SmallPlane(0, 0, 10, 10);
  ReleaseSpec release = testing::PointRelease({{5, 0}}, 3);
  release.height_m = 0.0;  // the cube's lower half would be underground
  release.orientation = Eigen::Quaterniond::Identity();
  const EnsembleReport report = RunEnsemble(scene, release, EnsembleOptions{});
  EXPECT_EQ(report.raised, 3);
  EXPECT_EQ(report.count(EndReason::kRest), 3);
}

TEST(RunEnsemble, RocksThatStayAtTheirReleaseAreCounted) {
  // A cube set down on flat ground never moves further than its own length (0.4 m): counted.
  const Scene flat = testing::SmallPlane(0, 0, 10, 10);
  ReleaseSpec release = testing::PointRelease({{5, 0}}, 3);
  release.height_m = 0.2;
  release.orientation = Eigen::Quaterniond::Identity();
  const EnsembleReport stayed = RunEnsemble(flat, release, EnsembleOptions{});
  EXPECT_EQ(stayed.stayed_at_release, 3);
  // Dropped 1 m onto a 40 degree slope, it tumbles away: none counted.
  const Scene steep = testing::SmallPlane(40, 40, 10, 10);
  release = testing::PointRelease({{5, 0}}, 3);
  const EnsembleReport moved = RunEnsemble(steep, release, EnsembleOptions{});
  EXPECT_EQ(moved.stayed_at_release, 0);
  EXPECT_EQ(moved.rocks, 3);
}

// A scene or release that was not checked is a programming error: debug builds stop at the
// entry, before any rock runs (release builds trust the caller, at no cost).
TEST(RunEnsembleDeathTest, AnUncheckedSceneOrReleaseStopsADebugBuild) {
#ifdef NDEBUG
  GTEST_SKIP() << "assertions are compiled out";
#else
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  Scene scene = testing::SmallPlane(0, 0, 10, 10);
  const ReleaseSpec release = testing::PointRelease({{5, 0}}, 1);
  scene.options.dt_s = 0;
  EXPECT_DEATH(RunEnsemble(scene, release, EnsembleOptions{}), "RunEnsemble needs a valid scene");
  EXPECT_DEATH(RunEnsemble(testing::SmallPlane(0, 0, 10, 10), ReleaseSpec{}, EnsembleOptions{}),
               "RunEnsemble needs a valid release");
#endif
}

}  // namespace
}  // namespace talus::ensemble
