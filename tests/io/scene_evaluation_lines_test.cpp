// [evaluation_lines] of a scene file (io/scene_evaluation_lines.cpp) through io::LoadScene: what
// scene_file_test.cpp does not cover -- a line whose vertices both lie off the DEM but whose
// segment crosses it is accepted (the check samples along the segments, not only the vertices),
// the vertices and names are kept as given, and malformed lists are errors naming the key.

#include <gtest/gtest.h>

#include <string>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// A 60 x 30 m plane (x 0 .. 60, y -15 .. 15, 1 m cells).
const std::string kScene = R"([terrain]
plane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[rock]
shape = { box = [0.5, 0.4, 0.3] }

[release]
points = [[5, 0]]

[evaluation_lines]
)";

std::string ErrorOf(const std::string& lines_table) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", kScene + lines_table);
  try {
    LoadScene((dir / "scene.toml").string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

SceneFile Load(const std::string& lines_table) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", kScene + lines_table);
  return LoadScene((dir / "scene.toml").string());
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// Both vertices beyond the DEM's sides (y = -40 and 40) with the segment across it at x = 30: a
// rock can cross it, so it loads; as does a polyline of three vertices, kept in order.
TEST(SceneEvaluationLines, ALineCrossingTheDemWithItsVerticesOffItLoads) {
  const SceneFile s = Load(
      "lines = [[[30, -40], [30, 40]], [[10, -5], [12.5, 0], [10, 5]]]\n"
      "names = [\"across\", \"bent\"]\n");
  ASSERT_EQ(s.evaluation_lines.size(), 2u);
  EXPECT_EQ(s.evaluation_lines[0].name, "across");
  EXPECT_EQ(s.evaluation_lines[0].vertices_m.front(), Eigen::Vector2d(30, -40));
  EXPECT_EQ(s.evaluation_lines[0].vertices_m.back(), Eigen::Vector2d(30, 40));
  EXPECT_NEAR(s.evaluation_lines[0].length_m(), 80, 1e-12);
  EXPECT_EQ(s.evaluation_lines[1].name, "bent");
  ASSERT_EQ(s.evaluation_lines[1].vertices_m.size(), 3u);
  EXPECT_EQ(s.evaluation_lines[1].vertices_m[1], Eigen::Vector2d(12.5, 0));
  // Two sides of 5.59 m: 2 sqrt(2.5^2 + 5^2).
  EXPECT_NEAR(s.evaluation_lines[1].length_m(), 2 * std::sqrt(2.5 * 2.5 + 25), 1e-12);
  // Wholly beyond one side (y from 20 to 40) it is an error, as scene_file_test checks elsewhere.
  EXPECT_HAS(ErrorOf("lines = [[[30, 20], [30, 40]]]\n"), "lies entirely outside the DEM");
}

TEST(SceneEvaluationLines, MalformedListsAreErrorsNamingTheKey) {
  EXPECT_HAS(ErrorOf("lines = \"north\"\n"),
             "scene.toml:11: evaluation_lines.lines: expected a list of lines, each a list of "
             "[x, y] points");
  EXPECT_HAS(ErrorOf("lines = [[[30, -10], [30, 10]]]\nnames = [7]\n"),
             "scene.toml:12: evaluation_lines.names: expected a list of names (strings)");
  EXPECT_HAS(ErrorOf("names = [\"a\"]\n"),
             "evaluation_lines.names: names are for the lines of 'lines'");
  EXPECT_HAS(ErrorOf("lines = [[30, -10], [30, 10]]\n"), "evaluation_lines.lines[0]");
  EXPECT_HAS(ErrorOf("lines = [[[30, -10], [30, 10, 2]]]\n"),
             "evaluation_lines.lines[0][1]: expected a list of 2 numbers");
}

}  // namespace
}  // namespace talus::io
