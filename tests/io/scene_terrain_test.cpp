// [terrain] of a scene file (io/scene_terrain.cpp) through io::LoadScene: the analytic plane's
// heights and grid against its closed form (z = max(0, L - x) tan(theta), nodes every cell_m over
// x 0 .. L + runout and y +-width/2), its description and spec kept for summary.json, the default
// ground by name, and the errors scene_file_test.cpp does not reach, naming file, line and key.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// [terrain] is first; [rock] and [release] follow.
const std::string kTail = R"(
[rock]
shape = { box = [0.5, 0.4, 0.3] }

[release]
points = [[5, 0]]
)";

SceneFile Load(const std::string& terrain) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", "[terrain]\n" + terrain + kTail);
  return LoadScene((dir / "scene.toml").string());
}

std::string ErrorOf(const std::string& terrain) {
  try {
    Load(terrain);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// slope 25 deg over 30 m, 12 m of runout, 20 m wide, 2 m cells: 22 x 11 nodes, y from -10; the
// height at x is max(0, 30 - x) tan(25 deg) (exact at nodes, bilinear between them: exact on the
// plane too, since it is linear in x within each cell except at the toe x = 30, a node).
TEST(SceneTerrain, PlaneHasTheHeightsAndGridOfItsSpec) {
  const SceneFile s = Load(
      "plane = { slope_deg = 25, slope_length_m = 30, runout_m = 12, width_m = 20, cell_m = 2 }\n"
      "default_ground = \"soft\"\n");
  const GridGeometry& g = s.scene.terrain.heights().grid;
  EXPECT_EQ(g.nx, 22);
  EXPECT_EQ(g.ny, 11);
  EXPECT_EQ(g.x0_m, 0);
  EXPECT_EQ(g.y0_m, -10);
  EXPECT_EQ(g.dx_m, 2);
  const double tan25 = std::tan(25 * std::numbers::pi / 180);
  for (double x : {0.0, 3.3, 17.0, 29.9, 30.0, 35.5, 42.0})
    for (double y : {-10.0, 0.7, 10.0}) {
      TerrainSample at;
      ASSERT_TRUE(s.scene.terrain.Sample(x, y, &at)) << x << ", " << y;
      EXPECT_NEAR(at.height_m, std::max(0.0, 30 - x) * tan25, 1e-12) << x << ", " << y;
    }
  TerrainSample on_slope;
  s.scene.terrain.Sample(10, 0, &on_slope);
  EXPECT_NEAR(on_slope.normal.dot(Eigen::Vector3d::UnitZ()), std::cos(25 * std::numbers::pi / 180),
              1e-12);
  TerrainSample outside;
  EXPECT_FALSE(s.scene.terrain.Sample(43, 0, &outside));
  ASSERT_TRUE(s.plane.has_value());
  EXPECT_EQ(s.plane->slope_deg, 25);
  EXPECT_EQ(s.plane->runout_m, 12);
  EXPECT_HAS(s.terrain_description, "plane 25 deg, ");
  EXPECT_HAS(s.terrain_description, " of 2 m");
  EXPECT_TRUE(s.crs_wkt.empty());
  EXPECT_EQ(s.scene.terrain.default_ground(), s.scene.ground.IndexOfName("soft"));
  EXPECT_FALSE(s.scene.terrain.has_ground_grid());
}

// A plane's keys not given take PlaneSpec's defaults (40 deg, 200 m + 150 m, 100 m wide, 2 m).
TEST(SceneTerrain, PlaneKeysDefaultToTheSpecsDefaults) {
  const SceneFile s = Load("plane = { slope_deg = 30 }\n");
  const PlaneSpec defaults;
  EXPECT_EQ(s.plane->slope_length_m, defaults.slope_length_m);
  EXPECT_EQ(s.plane->width_m, defaults.width_m);
  EXPECT_EQ(s.scene.terrain.heights().grid.nx,
            static_cast<int>((defaults.slope_length_m + defaults.runout_m) / defaults.cell_m) + 1);
}

TEST(SceneTerrain, ErrorsNameTheFileLineAndKey) {
  EXPECT_HAS(ErrorOf("default_ground = \"hard\"\n"),
             "scene.toml:1: terrain.dem: give exactly one of 'dem' and 'plane'");
  EXPECT_HAS(ErrorOf("plane = 35\n"),
             "scene.toml:2: terrain.plane: expected an inline table { slope_deg = ..., ... }");
  EXPECT_HAS(ErrorOf("plane = { cell_m = 500 }\n"), "cell_m = 500 is larger than the plane");
  EXPECT_HAS(ErrorOf("plane = { width_m = 0 }\n"), "width_m = 0 must be > 0");
  EXPECT_HAS(ErrorOf("plane = {}\nground_polygons = \"zones.gpkg\"\n"),
             "scene.toml:3: terrain.ground_polygons: expected an inline table { file = \"...\", "
             "field = \"...\" }");
  EXPECT_HAS(ErrorOf("plane = {}\nground_polygons = { file = \"zones.gpkg\" }\n"),
             "terrain.ground_polygons.field: missing: give the vector file and its category field");
  EXPECT_HAS(ErrorOf("plane = {}\ndefault_ground = \"medium_hrad\"\n"),
             "scene.toml:3: terrain.default_ground: unknown ground category 'medium_hrad' (did you "
             "mean 'medium_hard'?)");
}

}  // namespace
}  // namespace talus::io
