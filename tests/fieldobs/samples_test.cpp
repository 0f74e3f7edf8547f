#include "fieldobs/samples.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace talus::fieldobs
