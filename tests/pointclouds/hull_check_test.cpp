#include "pointclouds/hull_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pointclouds/convex_hull.hpp"
#include "solver/polyhedron.hpp"
#include "test_clouds.hpp"

namespace talus::pointclouds {
namespace {

HullCheck Check(const std::vector<Eigen::Vector3d>& points) {
  return CheckHull(points, ComputeMassProperties(ComputeConvexHull(points, "test"), 1.0).volume_m3);
}

// Clean scans of convex rocks, elongated up to 4:1 and with faces and corners: their dense core
// holds most of the hull and no point is far out, so no warning.
TEST(CheckHull, CleanScansOfConvexRocksAreNotDominated) {
  std::mt19937_64 rng(31);
  const std::vector<std::vector<Eigen::Vector3d>> scans = {
      testing::EllipsoidSurface(1, 1, 1, 5000, rng),
      testing::EllipsoidSurface(1.0, 0.7, 0.4, 5000, rng),
      testing::EllipsoidSurface(2.0, 0.5, 0.5, 5000, rng),
      testing::BoxSurface(2, 0.5, 0.5, 5000, rng),
      testing::BoxSurface(1, 1, 0.25, 5000, rng),
      testing::BoxInterior(2, 1, 0.6, 3000, rng)};
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const HullCheck c = Check(scans[k]);
    EXPECT_FALSE(c.Dominated()) << "scan " << k << ": ratio " << c.VolumeRatio();
    EXPECT_LT(c.VolumeRatio(), 1.5) << "scan " << k;  // well below kMaxVolumeRatio = 2
    EXPECT_LT(c.farthest_m, 1.6 * c.core_radius_m) << "scan " << k;  // below kFarFactor = 3
    EXPECT_EQ(c.far_points, 0u);
    EXPECT_EQ(c.Warning("scan.xyz"), "");
  }
}

// 1 % stray returns 3 .. 10 m off a rock of about 2 x 1.4 x 0.8 m: the hull is many times the
// rock's and the warning says so, with the numbers.
TEST(CheckHull, FarOutliersDominateAndAreReported) {
  std::mt19937_64 rng(32);
  auto points = testing::EllipsoidSurface(1.0, 0.7, 0.4, 5000, rng);
  const double clean_m3 = Check(points).hull_volume_m3;
  for (const auto& p : testing::FarOutliers(50, 3, 10, rng)) points.push_back(p);
  const HullCheck c = Check(points);
  EXPECT_TRUE(c.Dominated());
  EXPECT_GT(c.VolumeRatio(), 10);
  EXPECT_EQ(c.far_points, 50u);  // every outlier is beyond 3 core radii (about 1 m)
  EXPECT_NEAR(c.core_volume_m3, clean_m3, 0.2 * clean_m3);  // the core is the rock
  EXPECT_NEAR(c.centre_m.norm(), 0, 0.05);                  // the median ignores the outliers
  const std::string w = c.Warning("scan.xyz");
  EXPECT_NE(w.find("scan.xyz: a few points dominate the rock's hull"), std::string::npos) << w;
  EXPECT_NE(w.find("50 of 5050 points"), std::string::npos) << w;
}

// A single point far out is enough, even when it adds little volume (a thin spike).
TEST(CheckHull, OneFarPointIsReported) {
  std::mt19937_64 rng(33);
  auto points = testing::EllipsoidSurface(1, 1, 1, 2000, rng);
  points.emplace_back(0, 0, 4);
  const HullCheck c = Check(points);
  EXPECT_EQ(c.far_points, 1u);
  EXPECT_NEAR(c.farthest_m, 4, 0.05);
  EXPECT_TRUE(c.Dominated());
}

// Below 20 points the core is every point: small surveys (corners measured by total station)
// never warn.
TEST(CheckHull, SmallScansAreTheirOwnCore) {
  const HullCheck c = Check(testing::BoxCorners(3, 1, 0.2));
  EXPECT_DOUBLE_EQ(c.core_volume_m3, c.hull_volume_m3);
  EXPECT_FALSE(c.Dominated());
}

}  // namespace
}  // namespace talus::pointclouds
