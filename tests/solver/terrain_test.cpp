#include "solver/terrain.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace talus {
namespace {

// 3 x 3 nodes, 2 m spacing, origin (10, 20); heights z = x * y / 100 on the nodes (bilinear
// functions are reproduced exactly by bilinear interpolation).
Terrain Saddle() {
  Heightfield hf;
  hf.grid = {3, 3, 10.0, 20.0, 2.0, 2.0};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) hf.z_m.push_back((10.0 + 2 * i) * (20.0 + 2 * j) / 100);
  return Terrain(hf, 0);
}

TEST(Terrain, BilinearHeightAndPatchNormalAreExact) {
  const Terrain t = Saddle();
  TerrainSample s;
  ASSERT_TRUE(t.Sample(11.3, 22.7, &s));
  EXPECT_NEAR(s.height_m, 11.3 * 22.7 / 100, 1e-13);
  // Normal of z = x y / 100: (-y/100, -x/100, 1) normalised.
  const Eigen::Vector3d n = Eigen::Vector3d(-22.7 / 100, -11.3 / 100, 1).normalized();
  EXPECT_LT((s.normal - n).norm(), 1e-13);
  ASSERT_TRUE(t.Sample(14.0, 24.0, &s));  // the far corner is inside
  EXPECT_NEAR(s.height_m, 14.0 * 24.0 / 100, 1e-13);
}

TEST(Terrain, OutsideAndNodataAreReported) {
  Terrain t = Saddle();
  TerrainSample s;
  EXPECT_FALSE(t.Sample(9.99, 21, &s));
  EXPECT_FALSE(t.Sample(12, 24.01, &s));
  EXPECT_FALSE(t.Sample(std::nan(""), 21, &s));
  Heightfield hf = t.heights();
  hf.z_m[8] = std::numeric_limits<double>::quiet_NaN();  // node (2, 2)
  const Terrain holed(hf, 0);
  EXPECT_TRUE(holed.Sample(11, 21, &s));   // cell (0, 0) has no nodata corner
  EXPECT_FALSE(holed.Sample(13, 23, &s));  // cell (1, 1) touches node (2, 2)
  Terrain::LocalPlane plane;
  EXPECT_FALSE(holed.PlaneAround(12.5, 22.5, 0.2, &plane));  // cell (1, 1) is in the box
}

TEST(Terrain, LocalPlaneBoundsTheTerrainInTheBox) {
  // z = x y / 100 departs from its tangent plane at (11, 21) by (x - 11)(y - 21)/100, which is
  // largest, 0.01 m, at the nodes (10|12, 20|22) of the one cell covering the box.
  const Terrain t = Saddle();
  Terrain::LocalPlane plane;
  ASSERT_TRUE(t.PlaneAround(11, 21, 0.5, &plane));
  EXPECT_NEAR(plane.at.height_m, 2.31, 1e-14);
  EXPECT_NEAR(plane.slope_x, 0.21, 1e-14);
  EXPECT_NEAR(plane.slope_y, 0.11, 1e-14);
  EXPECT_NEAR(plane.deviation_m, 0.01, 1e-14);
  EXPECT_FALSE(t.PlaneAround(10.2, 21, 0.5, &plane));  // the box reaches beyond x0
}

TEST(Terrain, GroundGridUsesNearestCellAndDefault) {
  Terrain t = Saddle();
  EXPECT_EQ(t.GroundAt(11, 21), 0);
  GroundGrid g;
  g.grid = {2, 1, 11.0, 21.0, 2.0, 2.0};  // two cells centred at (11, 21) and (13, 21)
  g.index = {3, GroundGrid::kNoGround};
  t.SetGroundGrid(g);
  EXPECT_EQ(t.GroundAt(10.1, 21.9), 3);
  EXPECT_EQ(t.GroundAt(12.9, 21.0), 0);  // no value: default
  EXPECT_EQ(t.GroundAt(20, 21), 0);      // outside the ground grid: default
}

// Copies share the heights and the ground grid (calibration copies scenes for every evaluation)
// and answer exactly as the original; a default terrain has empty grids, not null ones.
TEST(Terrain, CopiesShareTheirGridsAndAnswerAlike) {
  Terrain t = Saddle();
  GroundGrid g;
  g.grid = {3, 3, 10.0, 20.0, 2.0, 2.0};
  g.index = {1, 2, 3, 4, 5, 6, 7, 8, GroundGrid::kNoGround};
  t.SetGroundGrid(g);
  const Terrain copy = t;
  EXPECT_TRUE(copy.SharesHeightsWith(t));
  EXPECT_EQ(&copy.ground_grid(), &t.ground_grid());
  TerrainSample a, b;
  ASSERT_TRUE(t.Sample(11.3, 21.7, &a));
  ASSERT_TRUE(copy.Sample(11.3, 21.7, &b));
  EXPECT_EQ(a.height_m, b.height_m);
  EXPECT_EQ(a.normal, b.normal);
  EXPECT_EQ(copy.GroundAt(12.1, 22.2), 5);
  const Terrain empty;
  EXPECT_FALSE(empty.has_ground_grid());
  EXPECT_EQ(empty.heights().z_m.size(), 0u);
  EXPECT_FALSE(empty.IsValid(nullptr));
}

TEST(Terrain, ValidityNamesTheProblem) {
  std::string why;
  EXPECT_TRUE(Saddle().IsValid(&why)) << why;
  Heightfield hf;
  hf.grid = {3, 3, 0, 0, 1, 1};
  hf.z_m.assign(8, 0.0);
  EXPECT_FALSE(Terrain(hf, 0).IsValid(&why));
  EXPECT_NE(why.find("8 values"), std::string::npos) << why;
  hf.z_m.assign(9, std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(Terrain(hf, 0).IsValid(&why));
  EXPECT_NE(why.find("nodata"), std::string::npos) << why;
}

TEST(PlaneSpec, BuildsTheRampWithTheKinkOnANode) {
  PlaneSpec p;  // 40 deg, 200 m + 150 m, 100 m wide, 2 m cells
  std::string why;
  EXPECT_TRUE(p.IsValid(&why)) << why;
  const Terrain t(MakePlaneHeightfield(p), 0);
  TerrainSample s;
  ASSERT_TRUE(t.Sample(50.5, 10.3, &s));
  EXPECT_NEAR(s.height_m, 149.5 * std::tan(40 * M_PI / 180), 1e-9);
  EXPECT_NEAR(std::acos(s.normal.z()) * 180 / M_PI, 40, 1e-9);
  ASSERT_TRUE(t.Sample(250, -49, &s));
  EXPECT_EQ(s.height_m, 0.0);
  EXPECT_FALSE(t.Sample(351, 0, &s));
  p.slope_deg = 95;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("slope_deg"), std::string::npos);
}

}  // namespace
}  // namespace talus
