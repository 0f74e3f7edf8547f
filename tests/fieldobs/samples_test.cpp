#include "fieldobs/samples.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "ensemble/runner.hpp"
#include "solver/shapes.hpp"

namespace talus::fieldobs {
namespace {

// Samples of an ensemble divided into parts (as MPI ranks run it), serialised and appended in
// order, equal the samples of the whole ensemble, bit for bit, for every quantity and run.
TEST(EnsembleSamples, PartsSerialisedAndAppendedEqualTheWhole) {
  Scene scene;
  scene.terrain = Terrain(MakePlaneHeightfield({35, 20, 20, 30, 1}),
                          scene.ground.IndexOfName("medium_hard"));
  scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.3), 2700);
  scene.options.max_time_s = 4;
  ensemble::ReleaseSpec release;
  for (int r = 0; r < 3; ++r) {
    ensemble::ReleaseRun run;
    run.id = "run" + std::to_string(r);
    run.xy_m = {2.0, -5.0 + 5 * r};
    run.height_m = 1.0;
    release.runs.push_back(run);
  }
  release.rocks_per_release = 4;
  release.seed = 3;
  ensemble::EnsembleOptions options;
  options.threads = 2;
  options.episodes = true;
  options.extra_recorders.push_back(SegmentRecorders(scene.terrain, {1.0, 1.0, 1.0}));
  EnsembleSamples whole(release);
  ensemble::RunEnsemble(scene, release, options, &whole);

  EnsembleSamples joined(release);
  for (const auto& [first, end] : {std::pair{0L, 5L}, {5L, 6L}, {6L, 12L}}) {
    EnsembleSamples part(release);
    options.first_rock = first;
    options.end_rock = end;
    ensemble::RunEnsemble(scene, release, options, &part);
    joined.Append(part.Serialize());
  }
  ASSERT_EQ(joined.rocks(), whole.rocks());
  EXPECT_EQ(joined.Serialize(), whole.Serialize());
  for (Quantity q : {Quantity::kRunout, Quantity::kImpactSpeedOut, Quantity::kScarLength,
                     Quantity::kSegmentMaxSpeed})
    for (const std::string run : {"", "run0", "run2"})
      EXPECT_EQ(joined.Values(q, run), whole.Values(q, run));
  EXPECT_FALSE(whole.Values(Quantity::kImpactSpeedOut, "").empty());  // the test sees episodes

  const std::string bytes = whole.Serialize();
  EnsembleSamples broken(release);
  EXPECT_THROW(broken.Append(bytes.substr(0, bytes.size() - 3)), std::runtime_error);
  EXPECT_THROW(broken.Append(bytes + "x"), std::runtime_error);
}

// Rocks that left the DEM are told apart from those that came to rest (deposits.png draws them
// apart): down a 45 degree plane 20 m long with 2 m of runout, 12 rocks released 1 m high at
// 1 m/s, half leave it over the foot's edge (measured: 6 of 12; the others end on it); their ends
// lie on that edge, x = 22 m (plus the last step's travel, under 0.1 m at 2 ms), and the parts
// keep the split.
TEST(EnsembleSamples, RocksThatLeftTheDemAreToldApart) {
  Scene scene;
  scene.terrain =
      Terrain(MakePlaneHeightfield({45, 20, 2, 30, 1}), scene.ground.IndexOfName("medium_hard"));
  scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.3), 2700);
  scene.options.max_time_s = 10;
  ensemble::ReleaseSpec release;
  ensemble::ReleaseRun run;
  run.id = "run0";
  run.xy_m = {2.0, 0.0};
  run.height_m = 1.0;
  run.velocity_m_s = {1.0, 0, 0};
  release.runs.push_back(run);
  release.rocks_per_release = 12;
  release.seed = 3;
  ensemble::EnsembleOptions options;
  options.threads = 2;
  EnsembleSamples whole(release);
  ensemble::RunEnsemble(scene, release, options, &whole);
  const auto left = whole.EndPositions("run0", true);
  const auto rest = whole.EndPositions("run0", false);
  std::printf("%zu of %ld rocks left the DEM\n", left.size(), whole.rocks());
  EXPECT_EQ(left.size() + rest.size(), whole.EndPositions("run0").size());
  EXPECT_GE(left.size(), 3u);
  EXPECT_GE(rest.size(), 3u);
  for (const Eigen::Vector2d& xy : left) {
    EXPECT_GT(xy.x(), 22.0 - 0.5) << xy.transpose();
    EXPECT_LT(xy.x(), 22.0 + 0.1) << xy.transpose();
  }
  EnsembleSamples joined(release);
  joined.Append(whole.Serialize());
  EXPECT_EQ(joined.EndPositions("run0", true), left);
}

}  // namespace
}  // namespace talus::fieldobs
