// The run outputs shared by talus simulate and merge (app/run_outputs.hpp), without running
// rocks: the quick-look's sample of rocks (about 40 paths, at least one per drawn release, the
// first rocks of each), the list of output names (every raster a scene can ask for is one, so
// that a later run can remove it), CommitOutputs' manifest (an earlier run's outputs that this run
// did not replace are removed, never a user's file) and --rock-range.

#include "app/run_outputs.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "common/error.hpp"
#include "ensemble/rasters.hpp"
#include "tests/test_tmp.hpp"

namespace talus::app {
namespace {

namespace fs = std::filesystem;

ensemble::ReleaseSpec Points(int releases, long rocks) {
  ensemble::ReleaseSpec r;
  for (int k = 0; k < releases; ++k) {
    ensemble::ReleaseGeometry g;
    g.rings = {{Eigen::Vector2d(k, 0)}};
    r.releases.push_back(g);
  }
  r.SetRocksPerRelease(rocks);
  return r;
}

// Counts per release of the rocks QuickLookSample draws.
std::vector<long> Drawn(const ensemble::ReleaseSpec& r) {
  std::vector<long> drawn(static_cast<std::size_t>(r.release_count()), 0);
  for (long rock = 0; rock < r.total_rocks(); ++rock)
    if (QuickLookSample(r, rock)) {
      const int which = r.ReleaseOf(rock);
      // The first rocks of the release, in order.
      EXPECT_EQ(rock - r.FirstRockOf(which), drawn[static_cast<std::size_t>(which)]) << rock;
      ++drawn[static_cast<std::size_t>(which)];
    }
  return drawn;
}

// One release of 1000 rocks: its first 40. Three of 100: ceil(40 / 3) = 14 each. A release with
// fewer rocks than its share: all of them. 250 releases: every 3rd (stride ceil(250 / 100)), 84
// drawn, one rock each (ceil(40 / 84) = 1).
TEST(QuickLookSample, AboutFortyPathsTheFirstRocksOfEachDrawnRelease) {
  EXPECT_EQ(Drawn(Points(1, 1000)), std::vector<long>{40});
  EXPECT_EQ(Drawn(Points(3, 100)), (std::vector<long>{14, 14, 14}));
  EXPECT_EQ(Drawn(Points(4, 5)), (std::vector<long>{5, 5, 5, 5}));
  const std::vector<long> many = Drawn(Points(250, 3));
  for (std::size_t k = 0; k < many.size(); ++k) EXPECT_EQ(many[k], k % 3 == 0 ? 1 : 0) << k;
  // Releases of unequal size (rocks by area): the share is capped by each release's rocks.
  ensemble::ReleaseSpec unequal = Points(2, 1);
  unequal.SetRocksPerRelease(std::vector<long>{3, 100});
  EXPECT_EQ(Drawn(unequal), (std::vector<long>{3, 20}));
}

TEST(TalusOutputNames, EveryRasterASceneCanAskForIsAnOutputName) {
  const std::vector<std::string> names = TalusOutputNames();
  const std::set<std::string> unique(names.begin(), names.end());
  EXPECT_EQ(unique.size(), names.size()) << "names are unique";
  for (int k = 0; k < ensemble::kRasterKindNames.size(); ++k) {
    const std::string kind = ensemble::kRasterKindNames.Name(k);
    const auto has = [&](const std::string& n) { return unique.count(n) == 1; };
    if (has(kind + ".tif")) continue;
    // A statistic raster: max, mean and every percentile the output may ask for (1 .. 99).
    EXPECT_TRUE(has(kind + "_max.tif")) << kind;
    EXPECT_TRUE(has(kind + "_mean.tif")) << kind;
    for (int p = 1; p <= 99; ++p) EXPECT_TRUE(has(kind + "_p" + std::to_string(p) + ".tif")) << kind;
  }
  for (const char* file : {"rocks.csv", "summary.json", "trajectories.h5", "quicklook.png",
                           "report.html", "partial.bin", "partial.json", "evaluation_lines.csv"})
    EXPECT_EQ(unique.count(file), 1u) << file;
  EXPECT_EQ(unique.count(kOutputManifest), 0u);
}

fs::path FreshDir(const std::string& name) {
  const fs::path dir = talus::testing::TestTmpRoot() / "talus_app_tests" / ("run_outputs." + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void Write(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string Read(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Run 1 writes rocks.csv and speed_max.tif; run 2 writes rocks.csv only: speed_max.tif of run 1
// is removed, a user's notes.txt and a talus-named file the manifest does not list are kept, and
// the manifest lists run 2's files and the run log (written after it, by main).
TEST(CommitOutputs, RemovesTheEarlierRunsOutputsThisRunDidNotReplaceAndNothingElse) {
  const fs::path dir = FreshDir("commit");
  Write(dir / "notes.txt", "mine");
  {
    StagingDirectory staging(dir.string());
    Write(staging.path("rocks.csv"), "run 1");
    Write(staging.path("speed_max.tif"), "run 1");
    CommitOutputs(staging, {"rocks.csv", "speed_max.tif"}, dir.string());
  }
  EXPECT_EQ(Read(dir / kOutputManifest), "rocks.csv\nspeed_max.tif\nrun.log\n");
  Write(dir / "energy_max.tif", "the user's own");
  {
    StagingDirectory staging(dir.string());
    Write(staging.path("rocks.csv"), "run 2");
    CommitOutputs(staging, {"rocks.csv"}, dir.string());
  }
  EXPECT_EQ(Read(dir / "rocks.csv"), "run 2");
  EXPECT_FALSE(fs::exists(dir / "speed_max.tif"));
  EXPECT_EQ(Read(dir / "notes.txt"), "mine");
  EXPECT_EQ(Read(dir / "energy_max.tif"), "the user's own");
  EXPECT_EQ(Read(dir / kOutputManifest), "rocks.csv\nrun.log\n");
  // A manifest naming a file that is no talus output (edited by hand) never removes it.
  Write(dir / kOutputManifest, "rocks.csv\nnotes.txt\n../escape.txt\n");
  {
    StagingDirectory staging(dir.string());
    Write(staging.path("summary.json"), "{}");
    CommitOutputs(staging, {"summary.json"}, dir.string());
  }
  EXPECT_FALSE(fs::exists(dir / "rocks.csv"));
  EXPECT_EQ(Read(dir / "notes.txt"), "mine");
  EXPECT_EQ(Read(dir / kOutputManifest), "summary.json\nrun.log\n");
}

TEST(ParseRockRange, ParsesAColonBAndNamesTheOptionOtherwise) {
  EXPECT_EQ(ParseRockRange("0:10"), (std::pair<long, long>{0, 10}));
  EXPECT_EQ(ParseRockRange("999:1000"), (std::pair<long, long>{999, 1000}));
  for (const char* bad : {"10", ":5", "3:", "-1:4", "a:b", "1:2:3", "1 :2", "0x1:4", ""}) {
    try {
      ParseRockRange(bad);
      ADD_FAILURE() << bad << " parsed";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()),
                std::string("--rock-range: expected A:B (rocks A .. B - 1, 0 <= A < B), got '") +
                    bad + "'");
    }
  }
  for (const char* empty : {"5:5", "7:3"}) {
    try {
      ParseRockRange(empty);
      ADD_FAILURE() << empty << " parsed";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), std::string("--rock-range ") + empty +
                                           ": the range is empty (B must be greater than A)");
    }
  }
}

}  // namespace
}  // namespace talus::app
