// [release] of a scene file (io/scene_release.cpp) through io::LoadScene: rocks by area per
// cell and per square metre against the polygon's area, and the errors scene_file_test.cpp does
// not reach (conflicting counts, area densities on points, a header-only run table, an empty block
// column, a single-impact table that is not a table or is combined with start keys, no release),
// each naming the file, line and key.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// A 60 x 30 m plane of 1 m cells (x 0 .. 60, y -15 .. 15); [release] is appended.
const std::string kHead = R"([terrain]
plane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[rock]
shape = { box = [0.5, 0.4, 0.3] }

[release]
)";

SceneFile Load(const std::string& release, const std::string& runs_csv = "") {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", kHead + release);
  if (!runs_csv.empty()) testing::WriteText(dir / "runs.csv", runs_csv);
  return LoadScene((dir / "scene.toml").string());
}

std::string ErrorOf(const std::string& release, const std::string& runs_csv = "") {
  try {
    Load(release, runs_csv);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// A 10 x 4 m rectangle (40 m^2, 40 cells of 1 m^2) and a 2 x 2 m square (4 m^2): 0.5 rocks per cell
// give round(20) and round(2) rocks; 0.3 per m^2 give round(12) and round(1.2) = 1; a density that
// rounds to 0 still starts one rock per polygon.
TEST(SceneRelease, RocksByAreaAreTheDensityTimesEachPolygonsArea) {
  const std::string polygons =
      "polygons = [[[10, -2], [20, -2], [20, 2], [10, 2]], [[30, 0], [32, 0], [32, 2], [30, 2]]]\n";
  const SceneFile per_cell = Load(polygons + "rocks_per_cell = 0.5\n");
  EXPECT_EQ(per_cell.release.RocksOf(0), 20);
  EXPECT_EQ(per_cell.release.RocksOf(1), 2);
  const SceneFile per_m2 = Load(polygons + "rocks_per_m2 = 0.3\n");
  EXPECT_EQ(per_m2.release.RocksOf(0), 12);
  EXPECT_EQ(per_m2.release.RocksOf(1), 1);
  const SceneFile sparse = Load(polygons + "rocks_per_m2 = 0.01\n");
  EXPECT_EQ(sparse.release.RocksOf(0), 1);
  EXPECT_EQ(sparse.release.RocksOf(1), 1);
}

TEST(SceneRelease, CountsAndAreaDensitiesThatConflictAreErrors) {
  EXPECT_HAS(ErrorOf("polygons = [[[10, -2], [20, -2], [20, 2], [10, 2]]]\nrocks = 5\n"
                     "rocks_per_cell = 1\n"),
             "scene.toml:10: release.rocks_per_cell: give one of rocks, rocks_per_m2 and "
             "rocks_per_cell, not rocks as well");
  EXPECT_HAS(ErrorOf("points = [[5, 0]]\nrocks_per_cell = 1\n"),
             "scene.toml:9: release.rocks_per_cell: rocks by area are for polygons only, but ");
  EXPECT_HAS(ErrorOf("points = [[5, 0]]\nrocks_per_cell = 1\n"), "is a point: give rocks instead");
  EXPECT_HAS(ErrorOf("polygons = [[[10, -2], [20, -2], [20, 2], [10, 2]]]\nrocks_per_cell = 0\n"),
             "release.rocks_per_cell: ");
  EXPECT_HAS(ErrorOf("rocks = 3\n"),
             "scene.toml:7: release.points: missing: give points, lines, polygons, a vector file, "
             "a run table (runs) or a single-impact table (single_impacts)");
}

TEST(SceneRelease, RunTableAndSingleImpactErrorsNameTheKey) {
  std::string e = ErrorOf("runs = \"runs.csv\"\n", "trajectory_id,x_m,y_m\n");
  EXPECT_HAS(e, "runs.csv: no run (the table has a header only)");
  e = ErrorOf("runs = \"runs.csv\"\nblock_column = \"\"\n", "trajectory_id,x_m,y_m\nr1,5,0\n");
  EXPECT_HAS(e, "scene.toml:9: release.block_column: empty: name a column of the run table");
  e = ErrorOf("single_impacts = \"impacts.csv\"\n");
  EXPECT_HAS(e, "scene.toml:8: release.single_impacts: expected an inline table { file = "
                "\"impacts.csv\", ... }");
  e = ErrorOf("single_impacts = { file = \"impacts.csv\" }\nheight_m = 2\n");
  EXPECT_HAS(e, "scene.toml:9: release.height_m: a single-impact table sets each run's start "
                "(single_impacts)");
  e = ErrorOf("single_impacts = { at = [5, 0] }\n");
  EXPECT_HAS(e, "release.single_impacts.file: missing");
  e = ErrorOf("points = [[5, 0]]\nsingle_impacts = { file = \"impacts.csv\" }\n");
  EXPECT_HAS(e, "release.single_impacts: a single-impact table cannot be combined with points");
}

// [release] volume: block sizes from a distribution, each parameter checked and named.
TEST(SceneRelease, BlockSizeDistributionsLoadAndBadOnesNameTheKey) {
  const SceneFile power = Load(
      "points = [[5, 0]]\nvolume = { distribution = \"power_law\", min_m3 = 0.1, max_m3 = 10, "
      "exponent = 0.6 }\n");
  EXPECT_EQ(power.release.volume.kind, ensemble::VolumeDistribution::Kind::kPowerLaw);
  EXPECT_EQ(power.release.volume.exponent, 0.6);
  const SceneFile log_normal = Load(
      "points = [[5, 0]]\nvolume = { distribution = \"lognormal\", median_m3 = 1, sigma = 0.7 }\n");
  EXPECT_EQ(log_normal.release.volume.median_m3, 1);
  EXPECT_TRUE(std::isinf(log_normal.release.volume.max_m3));
  const std::string p = "points = [[5, 0]]\n";
  EXPECT_HAS(ErrorOf(p + "volume = { distribution = \"pareto\", min_m3 = 1, max_m3 = 2 }\n"),
             "scene.toml:9: release.volume.distribution: 'pareto' is not one of fixed, uniform");
  EXPECT_HAS(ErrorOf(p + "volume = { distribution = \"uniform\", min_m3 = 1 }\n"),
             "release.volume.max_m3: missing");
  EXPECT_HAS(ErrorOf(p + "volume = { distribution = \"uniform\", min_m3 = 2, max_m3 = 1 }\n"),
             "release.volume.max_m3");
  EXPECT_HAS(ErrorOf(p + "volume = { distribution = \"uniform\", min_m3 = 1, max_m3 = 2, "
                         "exponent = 1 }\n"),
             "release.volume.exponent: is not a parameter of the uniform distribution");
  EXPECT_HAS(ErrorOf(p + "volume = { distribution = \"power_law\", min_m3 = 0.1, max_m3 = 2, "
                         "exponent = -1 }\n"),
             "release.volume.exponent");
  EXPECT_HAS(ErrorOf(p + "volume = 2.0\n"), "release.volume: expected an inline table");
  EXPECT_HAS(ErrorOf("runs = \"runs.csv\"\nvolume = { distribution = \"uniform\", min_m3 = 1, "
                     "max_m3 = 2 }\n",
                     "trajectory_id,x_m,y_m\nr1,5,0\n"),
             "release.volume: block sizes are for release points");
}

// [release] source by slope: the plane rises at 30 deg for x in 0 .. 40 m and is flat to 60 m (1 m
// cells, y -15 .. 15). A cell is the square around a DEM node, cut at the outermost nodes; with
// slope_min_deg = 20 the cells of nodes x = 0 .. 39 are sources, 31 rows each; the node at the kink
// (x = 40) touches both faces and may count either way.
TEST(SceneRelease, SourceCellsBySlopeAreTheSteepCells) {
  const SceneFile scene = Load("source = { slope_min_deg = 20 }\nrocks = 3\n");
  const auto& releases = scene.release.releases;
  EXPECT_TRUE(releases.size() == 40 * 31 || releases.size() == 41 * 31) << releases.size();
  for (const auto& release : releases) {
    ASSERT_EQ(release.kind, ensemble::ReleaseGeometry::Kind::kPolygon);
    for (const Eigen::Vector2d& p : release.rings[0]) {
      EXPECT_LE(p.x(), 40.5);
      EXPECT_GE(p.x(), 0);
      EXPECT_LE(std::abs(p.y()), 15);
    }
  }
  EXPECT_EQ(scene.release.total_rocks(), 3 * static_cast<long>(releases.size()));
  EXPECT_HAS(ErrorOf("source = { slope_min_deg = 45 }\n"),
             "release.source.slope_min_deg: no source cell: no DEM cell is that steep");
  EXPECT_HAS(ErrorOf("source = { slope_min_deg = 95 }\n"), "release.source.slope_min_deg");
  EXPECT_HAS(ErrorOf("source = 3\n"), "release.source: expected an inline table");
  EXPECT_HAS(ErrorOf("source = { }\n"), "release.source.raster: missing");
  EXPECT_HAS(ErrorOf("source = { slope_min_deg = 20 }\nrocks_per_m2 = 0.1\n"),
             "release.rocks_per_m2: each source cell releases `rocks` rocks");
}

// [release] source by raster: the cells > 0 of a raster on the DEM's grid (here 61 x 31 cells of
// 1 m centred on the DEM's nodes) are sources; 0, negative and nodata cells are not; with a slope
// threshold as well, only the steep ones.
TEST(SceneRelease, SourceCellsFromARasterAreItsPositiveCells) {
  const auto dir = testing::FreshDir("sources");
  std::vector<std::vector<double>> rows(31, std::vector<double>(61, 0.0));
  // Row 0 is the north edge (y = 15); cell (i, j) from the south-west is rows[30 - j][i].
  rows[30 - 15][10] = 1;    // on the slope
  rows[30 - 15][11] = 2.5;  // any positive value
  rows[30 - 16][10] = -1;   // not a source
  rows[30 - 16][11] = -9999;  // nodata
  rows[30 - 15][50] = 1;    // on the flat
  testing::WriteGdalRaster(dir / "sources.tif", rows, {-0.5, 1, 0, 15.5, 0, -1}, 0, -9999.0);
  testing::WriteText(dir / "scene.toml",
                     kHead + "source = { raster = \"sources.tif\" }\nrocks = 2\n");
  const SceneFile all = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(all.release.releases.size(), 3u);
  const auto centre = [](const ensemble::ReleaseGeometry& g) {
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : g.rings[0]) c += p / 4;
    return c;
  };
  EXPECT_TRUE(centre(all.release.releases[0]).isApprox(Eigen::Vector2d(10, 0)));
  EXPECT_TRUE(centre(all.release.releases[1]).isApprox(Eigen::Vector2d(11, 0)));
  EXPECT_TRUE(centre(all.release.releases[2]).isApprox(Eigen::Vector2d(50, 0)));
  EXPECT_EQ(all.release.total_rocks(), 6);
  testing::WriteText(dir / "steep.toml",
                     kHead + "source = { raster = \"sources.tif\", slope_min_deg = 20 }\n");
  EXPECT_EQ(LoadScene((dir / "steep.toml").string()).release.releases.size(), 2u);
  // A raster whose positive cells all lie off the DEM gives no source.
  testing::WriteGdalRaster(dir / "off.tif", {{1, 1}, {1, 1}}, {500, 1, 0, 500, 0, -1}, 0,
                           std::nullopt);
  testing::WriteText(dir / "off.toml", kHead + "source = { raster = \"off.tif\" }\n");
  try {
    LoadScene((dir / "off.toml").string());
    ADD_FAILURE() << "a raster off the DEM was accepted";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "release.source.raster: no source cell: the raster has no cell > 0 on the DEM");
  }
}

}  // namespace
}  // namespace talus::io
