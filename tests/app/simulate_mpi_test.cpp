// End to end through mpirun: `mpirun -n R talus simulate` writes the bytes of a one-process run
// (summary.json's threads and timings aside), and a rank that fails or is lost ends the whole run
// with an error and no output, never a hang.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "run_talus.hpp"

namespace {

namespace fs = std::filesystem;
using talus::app::testing::RunCommand;

const std::string kScene = std::string(TALUS_SOURCE_DIR) + "/cases/tirol/scene.toml";

// mpirun as CI runs it: as root, more ranks than cores allowed, and a time limit so that a hang
// fails the test instead of stalling it.
std::string MpiRun(const std::string& ranks) {
  return "timeout -s KILL 120 " + std::string(TALUS_MPIEXEC) +
         " --oversubscribe --allow-run-as-root " + ranks;
}

std::string Talus() { return TALUS_BINARY; }

using talus::app::testing::OutputsWithoutTimings;

fs::path FreshDir(const std::string& name) {
  return talus::app::testing::FreshDir("talus_mpi_tests", name);
}

// Where ranks other than 0 stage, below $TMPDIR.
std::string Ranks() { return "talus-ranks-" + std::to_string(::geteuid()); }

// The real Tirol DEM crop with its CRS, 12 rocks with trajectories, every raster and two
// evaluation lines.
TEST(SimulateMpi, RanksTimesThreadsGiveTheOneProcessBytes) {
  const fs::path dir = FreshDir("identity");
  std::string log;
  const std::string args = " simulate " + kScene + " --rocks 12 --out ";
  ASSERT_EQ(RunCommand(Talus() + args + (dir / "single").string() + " --threads 1", &log), 0)
      << log;
  const auto single = OutputsWithoutTimings(dir / "single");
  ASSERT_EQ(single.size(), 21u);  // with rocks.gpkg and the list of outputs, .talus-outputs
  ASSERT_GT(single.at("evaluation_lines.csv").size(), 200u);  // rocks crossed
  for (const auto& [ranks, threads] : {std::pair{2, 1}, std::pair{2, 2}, std::pair{3, 1}}) {
    const std::string name = "mpi-" + std::to_string(ranks) + "x" + std::to_string(threads);
    ASSERT_EQ(RunCommand(MpiRun("-n " + std::to_string(ranks) + " " + Talus()) + args +
                             (dir / name).string() + " --threads " + std::to_string(threads),
                         &log),
              0)
        << log;
    EXPECT_NE(log.find(std::to_string(ranks) + " ranks"), std::string::npos) << log;
    const auto merged = OutputsWithoutTimings(dir / name);
    ASSERT_EQ(merged.size(), single.size()) << name;
    for (const auto& [file, bytes] : single)
      EXPECT_TRUE(merged.at(file) == bytes) << file << " differs for " << name;
  }
}

// cases/tirol with its 500 kJ net (scene_net.toml), 16 rocks (measured: 5 stopped, 2 overtop it, 1
// breaks through): barriers.csv, rocks.csv's endings and the summary's barriers are the
// one-process bytes for 1 and 2 threads and 2 and 3 ranks.
TEST(SimulateMpi, BarriersGiveTheOneProcessBytesForAnyRanksAndThreads) {
  const fs::path dir = FreshDir("barriers");
  std::string log;
  const std::string args = " simulate " + std::string(TALUS_SOURCE_DIR) +
                           "/cases/tirol/scene_net.toml --rocks 16 --out ";
  ASSERT_EQ(RunCommand(Talus() + args + (dir / "single").string() + " --threads 1", &log), 0)
      << log;
  const auto single = OutputsWithoutTimings(dir / "single");
  ASSERT_NE(single.at("barriers.csv").find(",stopped,"), std::string::npos);
  ASSERT_NE(single.at("barriers.csv").find(",broke_through,"), std::string::npos);
  ASSERT_EQ(RunCommand(Talus() + args + (dir / "threads").string() + " --threads 2", &log), 0)
      << log;
  EXPECT_TRUE(OutputsWithoutTimings(dir / "threads") == single) << "2 threads differ";
  for (int ranks : {2, 3}) {
    const std::string name = "mpi-" + std::to_string(ranks);
    ASSERT_EQ(RunCommand(MpiRun("-n " + std::to_string(ranks) + " " + Talus()) + args +
                             (dir / name).string() + " --threads 1",
                         &log),
              0)
        << log;
    const auto merged = OutputsWithoutTimings(dir / name);
    ASSERT_EQ(merged.size(), single.size()) << name;
    for (const auto& [file, bytes] : single)
      EXPECT_TRUE(merged.at(file) == bytes) << file << " differs for " << name;
  }
}

// cases/tirol with its forest (scene_forest.toml): the stands' trees are drawn on every rank from
// the same seed, so tree_impacts.csv, tree_hits.tif and the summary's forest are the one-process
// bytes for 2 threads and 2 ranks.
TEST(SimulateMpi, AForestGivesTheOneProcessBytesForAnyRanksAndThreads) {
  const fs::path dir = FreshDir("forest");
  std::string log;
  const std::string args = " simulate " + std::string(TALUS_SOURCE_DIR) +
                           "/cases/tirol/scene_forest.toml --rocks 8 --out ";
  ASSERT_EQ(RunCommand(Talus() + args + (dir / "single").string() + " --threads 1", &log), 0)
      << log;
  const auto single = OutputsWithoutTimings(dir / "single");
  ASSERT_NE(single.at("tree_impacts.csv").find(",1,\n"), std::string::npos) << "a stem broke";
  ASSERT_EQ(single.count("tree_hits.tif"), 1u);
  ASSERT_EQ(RunCommand(Talus() + args + (dir / "threads").string() + " --threads 2", &log), 0)
      << log;
  EXPECT_TRUE(OutputsWithoutTimings(dir / "threads") == single) << "2 threads differ";
  ASSERT_EQ(
      RunCommand(MpiRun("-n 2 " + Talus()) + args + (dir / "mpi").string() + " --threads 1", &log),
      0)
      << log;
  const auto merged = OutputsWithoutTimings(dir / "mpi");
  ASSERT_EQ(merged.size(), single.size());
  for (const auto& [file, bytes] : single)
    EXPECT_TRUE(merged.at(file) == bytes) << file << " differs for 2 ranks";
}

// Rank 1 is given a scene file that does not exist: every rank stops before any work, rank 0 says
// which rank failed and why, once, and nothing is written.
TEST(SimulateMpi, ABadInputOnOneRankEndsTheRunWithOneMessage) {
  const fs::path dir = FreshDir("bad_rank");
  const fs::path out = dir / "out";
  std::string log;
  const int code = RunCommand(
      MpiRun("-n 1 " + Talus() + " simulate " + kScene + " --out " + out.string() + " : -n 1 " +
             Talus() + " simulate " + (dir / "missing.toml").string() + " --out " + out.string()),
      &log);
  EXPECT_EQ(code, 2) << log;
  const std::string message = "talus simulate: rank 1: " + (dir / "missing.toml").string();
  const std::size_t at = log.find(message);
  EXPECT_NE(at, std::string::npos) << log;
  EXPECT_EQ(log.find("talus simulate:", at + 1), std::string::npos)
      << "more than one message: " << log;
  EXPECT_FALSE(fs::exists(out));
}

// Rank 1 runs another ensemble (another seed): refused before any work.
TEST(SimulateMpi, RanksWithDifferentEnsemblesAreRefused) {
  const fs::path dir = FreshDir("other_seed");
  const fs::path out = dir / "out";
  std::string log;
  const std::string run = " simulate " + kScene + " --rocks 4 --out " + out.string();
  EXPECT_EQ(
      RunCommand(MpiRun("-n 1 " + Talus() + run + " : -n 1 " + Talus() + run + " --seed 3"), &log),
      2)
      << log;
  EXPECT_NE(log.find("rank 1: started with another ensemble than rank 0"), std::string::npos)
      << log;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
}

// Rank 1 is killed (SIGKILL) half a second after it has created its staging directory, in the
// middle of its share of the 4000 rocks (2000 per rank, about 35 s of work on one core, so a fast
// machine cannot finish them first; waited for, not timed, so that a loaded machine's slow start
// does not kill it before it stages): the run ends within the time limit with a failure, --out
// holds neither outputs nor temporary files; the next run removes what the killed rank left in its
// $TMPDIR.
TEST(SimulateMpi, ALostRankEndsTheRunWithoutOutputs) {
  const fs::path dir = FreshDir("lost_rank");
  const fs::path out = dir / "out", tmp = dir / "tmp";
  fs::create_directories(out);
  fs::create_directories(tmp);
  std::string log;
  const std::string run = " simulate " + kScene + " --threads 1 --out " + out.string();
  const std::string env = "TMPDIR=" + tmp.string() + " ";
  // Rank 1 under a shell that waits (at most 30 s) for something in the staging directory, then
  // kills it and exits as `timeout -s KILL` would.
  const std::string killed =
      "sh -c '" + Talus() + run + " --rocks 4000 & p=$!; n=0; while [ -z \"$(ls -A " +
      (tmp / Ranks()).string() +
      " 2>/dev/null)\" ] && [ $n -lt 600 ]; do sleep 0.05; n=$((n+1)); done; sleep 0.5; "
      "kill -KILL $p; wait $p; exit 137'";
  const int code =
      RunCommand(env + MpiRun("-n 1 " + Talus() + run + " --rocks 4000 : -n 1 " + killed), &log);
  EXPECT_NE(code, 0) << log;
  EXPECT_NE(code, -1) << log;  // ended by itself, not by the test's time limit
  EXPECT_TRUE(fs::is_empty(out)) << log;
  ASSERT_FALSE(fs::is_empty(tmp / Ranks()));  // the killed rank's staging directory
  ASSERT_EQ(RunCommand(env + MpiRun("-n 2 " + Talus()) + run + " --rocks 2", &log), 0) << log;
  EXPECT_TRUE(fs::is_empty(tmp / Ranks())) << log;
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

// $TMPDIR/talus-ranks-<uid> a symbolic link someone planted: ranks other than 0 refuse to stage
// there (they followed it, and removed a directory outside --out through it); the run fails with
// the reason and the link's target is untouched.
TEST(SimulateMpi, AStagingDirectoryThatIsALinkIsRefused) {
  const fs::path dir = FreshDir("ranks_link");
  const fs::path out = dir / "out", tmp = dir / "tmp", victim = dir / "victim";
  fs::create_directories(tmp);
  fs::create_directories(victim / ".precious.talus-tmp-999999");
  std::ofstream(victim / ".precious.talus-tmp-999999" / "file") << "data";
  fs::create_directory_symlink(victim, tmp / Ranks());
  std::string log;
  const int code =
      RunCommand("TMPDIR=" + tmp.string() + " " + MpiRun("-n 2 " + Talus()) + " simulate " +
                     kScene + " --threads 1 --rocks 2 --out " + out.string(),
                 &log);
  EXPECT_NE(code, 0) << log;
  EXPECT_NE(log.find(Ranks() + ": is a symbolic link"), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(victim / ".precious.talus-tmp-999999" / "file"));
  EXPECT_EQ(std::distance(fs::directory_iterator(victim), fs::directory_iterator()), 1);
  EXPECT_FALSE(fs::exists(out / "summary.json"));
}

}  // namespace
