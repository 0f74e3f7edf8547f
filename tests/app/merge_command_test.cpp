// End to end through the talus program: `talus simulate --rock-range` parts merged by
// `talus merge` give the single run's outputs byte for byte, for any split and order; parts that
// overlap, leave rocks out or come from different runs are refused with a clear message.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_talus.hpp"

namespace {

namespace fs = std::filesystem;
using talus::app::testing::RunCommand;
using talus::app::testing::Slurp;

// A small slope with every output: 2 releases x 5 rocks, two evaluation lines that some cross.
const std::string kScene = talus::app::testing::SmallSlopeScene(5, R"(trajectories = true
trajectory_interval_s = 0.05
rasters = ["speed", "energy", "jump_height", "passages", "deposits", "reach_probability"]
percentiles = [50, 95, 99]
geopackage = true
)",
                                                                R"([evaluation_lines]
lines = [[[5, -6], [5, 6]], [[6, -6], [6, 0], [6, 6]]]
names = ["barrier A", "net, lower"]
)");

std::string Talus(const std::string& arguments) {
  return std::string(TALUS_BINARY) + " " + arguments;
}

using talus::app::testing::OutputsWithoutTimings;

class MergeCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = talus::app::testing::FreshDir(
        "talus_merge_tests", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    scene_ = dir_ / "scene.toml";
    talus::app::testing::Write(scene_, kScene);
  }
  // Runs rocks `range` ("A:B") into <dir>/part-A-B with `threads`; returns that directory.
  fs::path Part(const std::string& range, int threads = 1, const std::string& extra = "") {
    std::string name = "part-" + range;
    name[name.find(':')] = '-';
    fs::path out = dir_ / name;
    std::string log;
    EXPECT_EQ(RunCommand(Talus("simulate " + scene_.string() + " --out " + out.string() +
                               " --rock-range " + range + " --threads " + std::to_string(threads) +
                               " " + extra),
                         &log),
              0)
        << log;
    return out;
  }
  // `talus merge parts... --out <dir>/merged`; its exit code, output in *log.
  int Merge(const std::vector<fs::path>& parts, std::string* log,
            const std::string& out = "merged") {
    std::string command = "merge";
    for (const fs::path& p : parts) command.append(" ").append(p.string());
    return RunCommand(Talus(command + " --out " + (dir_ / out).string()), log);
  }
  // The whole run in one process (2 threads) into <dir>/single; its outputs without timings.
  std::map<std::string, std::string> SingleRun() {
    std::string log;
    EXPECT_EQ(RunCommand(Talus("simulate " + scene_.string() + " --out " +
                               (dir_ / "single").string() + " --threads 2"),
                         &log),
              0)
        << log;
    return OutputsWithoutTimings(dir_ / "single");
  }
  fs::path dir_, scene_;
};

TEST_F(MergeCommand, AnySplitInAnyOrderGivesTheSingleRunsBytes) {
  std::string log;
  const auto single = SingleRun();
  // 3 x (max, mean, p50, p95, p99) + 3 count rasters + 8 files + the list of outputs
  // (.talus-outputs): every output is compared
  ASSERT_EQ(single.size(), 27u);
  // Some rocks cross, and not every one: the rows to merge are not trivial.
  const std::string& crossings = single.at("evaluation_lines.csv");
  EXPECT_GT(std::count(crossings.begin(), crossings.end(), '\n'), 3);
  EXPECT_NE(single.at("evaluation_lines_summary.csv").find("\nbarrier A,12,10,"), std::string::npos)
      << single.at("evaluation_lines_summary.csv");

  const std::vector<std::vector<std::string>> splits = {
      {"0:10"}, {"5:10", "0:5"}, {"9:10", "0:1", "4:9", "1:4"}};
  int k = 0;
  for (const auto& split : splits) {
    std::vector<fs::path> parts;
    for (const std::string& range : split) parts.push_back(Part(range, 1 + (k++ % 2)));
    const std::string out = "merged-" + std::to_string(split.size());
    ASSERT_EQ(Merge(parts, &log, out), 0) << log;
    const auto merged = OutputsWithoutTimings(dir_ / out);
    ASSERT_EQ(merged.size(), single.size());
    for (const auto& [name, bytes] : single)
      EXPECT_TRUE(merged.at(name) == bytes) << name << " differs for a split into " << split.size();
  }
}

// Rocks per area (a polygon of 18 m^2 at 0.5 rocks/m^2: 9 rocks) and Cloud-Optimised GeoTIFFs:
// the rock count comes from the polygon's area in every part, and the COG rasters merge to the
// single run's bytes as plain GeoTIFFs do.
TEST_F(MergeCommand, RocksPerAreaAndCloudOptimisedRastersMergeToTheSingleRunsBytes) {
  talus::app::testing::Write(scene_, R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_hard"
[rock]
shape = { box = [0.4, 0.4, 0.3] }
[release]
polygons = [[[2, -3], [5, -3], [5, 3], [2, 3]]]
rocks_per_m2 = 0.5
[solver]
max_time_s = 4
[output]
rasters = ["speed", "passages", "reach_probability"]
raster_format = "cog"
)");
  std::string log;
  const auto single = SingleRun();
  EXPECT_NE(single.at("summary.json").find("\"rocks\": 9"), std::string::npos)
      << single.at("summary.json");
  ASSERT_EQ(Merge({Part("4:9"), Part("0:4", 2)}, &log), 0) << log;
  const auto merged = OutputsWithoutTimings(dir_ / "merged");
  ASSERT_EQ(merged.size(), single.size());
  for (const auto& [name, bytes] : single) EXPECT_TRUE(merged.at(name) == bytes) << name;
}

// A forest: tree_impacts.csv, tree_hits.tif and summary.json's "forest" merge to the single run's
// bytes (the stand's trees are drawn alike in every part).
TEST_F(MergeCommand, AForestMergesToTheSingleRunsBytes) {
  talus::app::testing::Write(
      scene_, talus::app::testing::SmallSlopeScene(10, "rasters = [\"tree_hits\"]\n", R"([forest]
stands = [{ polygon = [[5, -5], [16, -5], [16, 5], [5, 5]], stems_per_ha = 4000, dbh_cm = 8, dbh_sd_cm = 2 }]
)"));
  std::string log;
  const auto single = SingleRun();
  const std::string& rows = single.at("tree_impacts.csv");
  EXPECT_GT(std::count(rows.begin(), rows.end(), '\n'), 1) << rows;
  ASSERT_EQ(single.count("tree_hits.tif"), 1u);
  const auto summary = nlohmann::json::parse(single.at("summary.json"));
  EXPECT_GT(summary.at("forest").at("trees").get<int>(), 0);
  EXPECT_GT(summary.at("forest").at("impacts").at("rocks_hitting").get<int>(), 0);
  std::vector<fs::path> parts = {Part("7:20"), Part("0:7", 2)};  // 10 rocks at each release
  ASSERT_EQ(Merge(parts, &log), 0) << log;
  const auto merged = OutputsWithoutTimings(dir_ / "merged");
  ASSERT_EQ(merged.size(), single.size());
  for (const auto& [name, bytes] : single) EXPECT_TRUE(merged.at(name) == bytes) << name;
}

// Barriers: a net that stops some rocks and is broken through by others (measured: 2 and 2 of 10),
// and a wall behind it that one of those breaks through. barriers.csv, barriers_summary.csv,
// rocks.csv's end_barrier and summary.json's "barriers" merge to the single run's bytes (threads 1
// and 2 in the parts, 2 in the single run).
TEST_F(MergeCommand, BarriersMergeToTheSingleRunsBytes) {
  talus::app::testing::Write(scene_, talus::app::testing::SmallSlopeScene(5, "", R"([[barriers]]
name = "net, upper"
type = "flexible_net"
line = [[5, -6], [5, 6]]
height_m = 0.4
capacity_kj = 0.3
[[barriers]]
name = "wall"
type = "rigid_wall"
line = [[6, -6], [6, 0], [6, 6]]
height_m = 1
capacity_kj = 0.05
)"));
  std::string log;
  const auto single = SingleRun();
  const std::string& rows = single.at("barriers.csv");
  EXPECT_NE(rows.find(",stopped,"), std::string::npos) << rows;
  EXPECT_NE(rows.find(",broke_through,"), std::string::npos) << rows;
  EXPECT_NE(single.at("rocks.csv").find(",barrier,"), std::string::npos);
  const auto summary = nlohmann::json::parse(single.at("summary.json"));
  EXPECT_EQ(summary.at("barriers").size(), 2u);
  EXPECT_GT(summary.at("ends").at("barrier").get<int>(), 0);
  for (const auto& split :
       std::vector<std::vector<std::string>>{{"3:10", "0:3"}, {"0:2", "2:7", "7:10"}}) {
    std::vector<fs::path> parts;
    int k = 0;
    for (const std::string& range : split) parts.push_back(Part(range, 1 + (k++ % 2)));
    const std::string out = "merged-" + std::to_string(split.size());
    ASSERT_EQ(Merge(parts, &log, out), 0) << log;
    const auto merged = OutputsWithoutTimings(dir_ / out);
    ASSERT_EQ(merged.size(), single.size());
    for (const auto& [name, bytes] : single)
      EXPECT_TRUE(merged.at(name) == bytes) << name << " differs for a split into " << split.size();
  }
}

TEST_F(MergeCommand, OverlappingPartsAreRefused) {
  std::string log;
  EXPECT_EQ(Merge({Part("0:6"), Part("4:10")}, &log), 2);
  EXPECT_NE(log.find("rocks 4:10 of"), std::string::npos) << log;
  EXPECT_NE(log.find("overlap rocks 0:6"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir_ / "merged" / "summary.json"));
}

TEST_F(MergeCommand, MissingRocksAreRefused) {
  std::string log;
  EXPECT_EQ(Merge({Part("0:4"), Part("6:10")}, &log), 2);
  EXPECT_NE(log.find("rocks 4:6 of 10 are in no partial result"), std::string::npos) << log;
  EXPECT_EQ(Merge({Part("0:4")}, &log), 2);
  EXPECT_NE(log.find("rocks 4:10 of 10 are in no partial result"), std::string::npos) << log;
}

TEST_F(MergeCommand, PartsOfDifferentRunsAreRefused) {
  std::string log;
  const fs::path a = Part("0:5");
  // Another seed.
  const fs::path b = dir_ / "other-seed";
  ASSERT_EQ(RunCommand(Talus("simulate " + scene_.string() + " --out " + b.string() +
                             " --rock-range 5:10 --seed 99"),
                       &log),
            0);
  EXPECT_EQ(Merge({a, b}, &log), 2);
  EXPECT_NE(log.find("parts of different runs: seeds 1 and 99"), std::string::npos) << log;
  // Another scene (the same scene file, edited).
  const fs::path c = dir_ / "other-scene";
  std::string edited = kScene;
  edited.replace(edited.find("max_time_s = 4"), 14, "max_time_s = 5");
  const fs::path scene2 = dir_ / "scene2.toml";
  talus::app::testing::Write(scene2, edited);
  ASSERT_EQ(RunCommand(Talus("simulate " + scene2.string() + " --out " + c.string() +
                             " --rock-range 5:10"),
                       &log),
            0);
  EXPECT_EQ(Merge({a, c}, &log), 2);
  EXPECT_NE(log.find("parts of different runs: scenes (inputs hash)"), std::string::npos) << log;
  // A part whose version differs (its partial.json edited).
  const fs::path d = Part("5:10");
  std::string info = Slurp(d / "partial.json");
  info.replace(info.find("\"talus_version\": \""), 18, "\"talus_version\": \"0.0.1-");
  talus::app::testing::Write(d / "partial.json", info);
  EXPECT_EQ(Merge({a, d}, &log), 2);
  EXPECT_NE(log.find("parts of different runs: talus versions"), std::string::npos) << log;
  // A directory that is not a complete part.
  EXPECT_EQ(Merge({a, dir_}, &log), 2);
  EXPECT_NE(log.find("not a complete partial result"), std::string::npos) << log;
}

// Parts whose files were swapped, cut or damaged since they ran (their partial.json's sizes and
// checksums no longer match) are refused as bad input, naming the file; nothing is written.
TEST_F(MergeCommand, PartsWithChangedFilesAreRefused) {
  std::string log;
  const fs::path a = Part("0:5"), b = Part("5:10");
  const std::string rocks = Slurp(b / "rocks.csv"), bin = Slurp(b / "partial.bin");
  talus::app::testing::Write(b / "rocks.csv", Slurp(a / "rocks.csv"));  // a's rows twice
  EXPECT_EQ(Merge({a, b}, &log), 2);
  EXPECT_NE(log.find((b / "rocks.csv").string() + ": "), std::string::npos) << log;
  EXPECT_NE(log.find("changed or damaged since the part was run"), std::string::npos) << log;
  talus::app::testing::Write(b / "rocks.csv",
                             rocks.substr(0, rocks.rfind('\n', rocks.size() - 2) + 1));
  EXPECT_EQ(Merge({a, b}, &log), 2);  // its last row deleted
  EXPECT_NE(log.find((b / "rocks.csv").string() + ": "), std::string::npos) << log;
  talus::app::testing::Write(b / "rocks.csv", rocks);
  std::string flipped = bin;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 1);
  talus::app::testing::Write(b / "partial.bin", flipped);
  EXPECT_EQ(Merge({a, b}, &log), 2);
  EXPECT_NE(log.find((b / "partial.bin").string() + ": "), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir_ / "merged" / "summary.json"));
  talus::app::testing::Write(b / "partial.bin", bin);
  EXPECT_EQ(Merge({a, b}, &log), 0) << log;  // as they were: merged
}

TEST_F(MergeCommand, ASceneChangedSinceThePartsRanIsRefused) {
  std::string log;
  const fs::path a = Part("0:10");
  std::string edited = kScene;
  edited.replace(edited.find("max_time_s = 4"), 14, "max_time_s = 5");
  talus::app::testing::Write(scene_, edited);
  EXPECT_EQ(Merge({a}, &log), 2);
  EXPECT_NE(log.find("changed since this part was run"), std::string::npos) << log;
}

// A part that an older talus wrote (partial.json format 3, FNV-1a checksums) is refused as bad
// input naming its partial.json and the rocks to run again; nothing is written.
TEST_F(MergeCommand, APartOfAnOlderTalusIsRefusedSayingWhatToRunAgain) {
  std::string log;
  const fs::path a = Part("0:5"), b = Part("5:10");
  nlohmann::ordered_json info = nlohmann::ordered_json::parse(Slurp(b / "partial.json"));
  info["format_version"] = 3;
  info["inputs_hash_fnv1a64"] = "cbf29ce484222325";
  info.erase("inputs_sha256");
  for (auto& [name, entry] : info["files"].items()) {
    entry.erase("sha256");
    entry["fnv1a64"] = "af63bd4c8601b7df";
  }
  talus::app::testing::Write(b / "partial.json", info.dump(2) + "\n");
  EXPECT_EQ(Merge({a, b}, &log), 2);
  EXPECT_NE(log.find("talus merge: " + (b / "partial.json").string() +
                     ": a part written by an older talus (partial result format 3, this talus "
                     "reads 5; its checksums are FNV-1a, this talus checks SHA-256): run the part "
                     "again with this talus (talus simulate " +
                     scene_.string() + " --rock-range 5:10 and the options it ran with)"),
            std::string::npos)
      << log;
  EXPECT_FALSE(fs::exists(dir_ / "merged"));
}

// On a terminal (script(1) gives the program one) merge shows its phases as one status line:
// checking the parts' bytes, merging each output, writing the rasters and summary; --quiet
// silences it with the information, and off a terminal there is none. run.log keeps what was
// said, never the progress.
TEST_F(MergeCommand, ProgressOnATerminalQuietSilencesItAndRunLogKeepsWhatWasSaid) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  const fs::path a = Part("0:4"), b = Part("4:10");
  const auto merge = [&](const std::string& out, const std::string& more, bool terminal) {
    const std::string command =
        Talus("merge " + a.string() + " " + b.string() + " --out " + (dir_ / out).string() + more);
    std::string output;
    EXPECT_EQ(RunCommand(terminal ? "script -qec '" + command + "' /dev/null" : command, &output),
              0)
        << output;
    return output;
  };
  const std::string talkative = merge("out", "", true);
  for (const char* phase :
       {"\rChecking the parts [", " MB  ", "\rMerging rocks.csv [", "\rMerging trajectories.h5 [",
        " 10/10 rocks ", "\rMerging evaluation_lines.csv [",
        "\rMerging the rasters (partial.bin) [", "\rWriting the outputs [", " files  "})
    EXPECT_NE(talkative.find(phase), std::string::npos) << phase << "\n" << talkative;
  EXPECT_NE(talkative.find("Merged 2 parts of "), std::string::npos) << talkative;
  const std::string quiet = merge("quiet", " --quiet", true);
  EXPECT_EQ(quiet.find("[#"), std::string::npos) << quiet;
  EXPECT_EQ(quiet.find("Merging"), std::string::npos) << quiet;
  EXPECT_EQ(quiet.find("Merged"), std::string::npos) << quiet;
  const std::string piped = merge("piped", "", false);
  EXPECT_EQ(piped.find('\r'), std::string::npos) << piped;
  EXPECT_EQ(piped.find("Checking the parts"), std::string::npos) << piped;
  EXPECT_NE(piped.find("Merged 2 parts of "), std::string::npos) << piped;
  const std::string log = Slurp(dir_ / "out" / "run.log");
  for (const char* line :
       {"command: ", " merge ", "\nMerged 2 parts of ", "\nWrote ", "finished: exit 0"})
    EXPECT_NE(log.find(line), std::string::npos) << line << "\n" << log;
  EXPECT_EQ(log.find("[#"), std::string::npos) << log;  // progress is not kept
  EXPECT_EQ(log.find("Checking the parts"), std::string::npos) << log;
}

TEST_F(MergeCommand, BadRockRangesAreRefusedBeforeAnyWork) {
  for (const std::string range : {"5", "5:5", "7:3", "a:4", "0:11", "-1:3"}) {
    std::string log;
    EXPECT_EQ(RunCommand(Talus("simulate " + scene_.string() + " --out " + (dir_ / "bad").string() +
                               " --rock-range " + range),
                         &log),
              2)
        << range;
    EXPECT_NE(log.find("--rock-range"), std::string::npos) << range << ": " << log;
    EXPECT_FALSE(fs::exists(dir_ / "bad" / "partial.json"));
  }
}

}  // namespace
