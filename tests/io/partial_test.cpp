#include "io/partial.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/error.hpp"
#include "tests/test_tmp.hpp"

namespace talus::io {
namespace {

PartialInfo Part(const std::string& dir, long first, long end, long total = 10) {
  PartialInfo p;
  p.dir = dir;
  p.version = "1.0";
  p.scene = "scene.toml";
  p.scene_file = "/data/scene.toml";
  p.inputs_hash = "abc";
  p.seed = 1;
  p.solver_preset = "default";
  p.rocks_per_release = total;
  p.total_rocks = total;
  p.first_rock = first;
  p.end_rock = end;
  p.counts.rocks = end - first;
  return p;
}

std::string Message(const std::vector<PartialInfo>& parts) {
  try {
    CheckPartials(parts);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CheckPartials, AcceptsATilingInAnyOrderAndSortsIt) {
  const auto parts = CheckPartials({Part("c", 7, 10), Part("a", 0, 3), Part("b", 3, 7)});
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].dir, "a");
  EXPECT_EQ(parts[1].dir, "b");
  EXPECT_EQ(parts[2].dir, "c");
}

TEST(CheckPartials, NamesOverlapsAndMissingRocks) {
  EXPECT_EQ(Message({Part("a", 0, 6), Part("b", 4, 10)}), "rocks 4:10 of b overlap rocks 0:6 of a");
  EXPECT_EQ(Message({Part("a", 0, 4), Part("b", 6, 10)}),
            "rocks 4:6 of 10 are in no partial result (the next part, b, starts at rock 6)");
  EXPECT_EQ(Message({Part("a", 0, 4)}), "rocks 4:10 of 10 are in no partial result");
  EXPECT_EQ(Message({Part("a", 2, 10)}),
            "rocks 0:2 of 10 are in no partial result (the next part, a, starts at rock 2)");
  EXPECT_EQ(Message({}), "no partial results to merge");
}

TEST(CheckPartials, NamesWhatDiffersBetweenRuns) {
  PartialInfo b = Part("b", 5, 10);
  b.seed = 2;
  EXPECT_EQ(Message({Part("a", 0, 5), b}), "a and b are parts of different runs: seeds 1 and 2");
  b = Part("b", 5, 10);
  b.version = "1.1";
  EXPECT_EQ(Message({Part("a", 0, 5), b}),
            "a and b are parts of different runs: talus versions 1.0 and 1.1");
  b = Part("b", 5, 10);
  b.inputs_hash = "abd";
  EXPECT_NE(Message({Part("a", 0, 5), b}).find("different runs: scenes (inputs hash)"),
            std::string::npos);
  b = Part("b", 5, 10);
  b.solver_preset = "fast";  // talus simulate --preset fast for one part only
  EXPECT_EQ(Message({Part("a", 0, 5), b}),
            "a and b are parts of different runs: solver presets default and fast");
}

TEST(ReadPartialInfo, ADirectoryWithoutPartialJsonIsNotAPart) {
  const auto dir = talus::testing::TestTmpRoot() / "talus_partial_test_empty";
  std::filesystem::create_directories(dir);
  EXPECT_THROW(ReadPartialInfo(dir.string()), InputError);
  std::ofstream(dir / "partial.json") << "{\"format\": \"something else\"}";
  try {
    ReadPartialInfo(dir.string());
    FAIL() << "accepted a partial.json of another format";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("partial.json"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace talus::io
