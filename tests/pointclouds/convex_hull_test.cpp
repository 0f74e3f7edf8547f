#include "pointclouds/convex_hull.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/error.hpp"
#include "test_clouds.hpp"

namespace talus::pointclouds {
namespace {

using testing::IsClosedAndOriented;

std::string HullError(const std::vector<Eigen::Vector3d>& points) {
  try {
    ComputeConvexHull(points, "scan.xyz");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ComputeConvexHull, BoxCornersAmongInteriorPoints) {
  std::mt19937_64 rng(1);
  auto points = testing::BoxInterior(2, 1, 0.5, 500, rng);
  const auto corners = testing::BoxCorners(2, 1, 0.5);
  points.insert(points.begin() + 100, corners.begin(), corners.end());
  const Polyhedron hull = ComputeConvexHull(points, "box");
  EXPECT_EQ(hull.vertices_m.size(), 8u);
  EXPECT_EQ(hull.triangles.size(), 12u);
  EXPECT_TRUE(IsClosedAndOriented(hull));
  // Vertices are the input corners themselves, bit for bit.
  for (const auto& v : hull.vertices_m)
    EXPECT_NE(std::find(corners.begin(), corners.end(), v), corners.end());
  EXPECT_NEAR(ComputeMassProperties(hull, 1.0).volume_m3, 1.0, 1e-15);
}

TEST(ComputeConvexHull, KeepsDoublePrecisionBeyondFloat) {
  // Corners 1e-10 m apart from float-representable values: the hull keeps the double inputs.
  auto points = testing::BoxCorners(1, 1, 1);
  for (auto& p : points) p += Eigen::Vector3d::Constant(1e-10);
  const Polyhedron hull = ComputeConvexHull(points, "box");
  for (const auto& v : hull.vertices_m)
    EXPECT_NE(std::find(points.begin(), points.end(), v), points.end());

  // A 1 cm pebble at georeferenced coordinates, where float resolution is 0.25 m.
  std::mt19937_64 rng(6);
  std::vector<Eigen::Vector3d> pebble = testing::BoxInterior(0.01, 0.01, 0.01, 100, rng);
  const auto corners = testing::BoxCorners(0.01, 0.01, 0.01);
  pebble.insert(pebble.end(), corners.begin(), corners.end());
  const Eigen::Vector3d shift(2600123.4567, 1200456.789, 1543.21);
  for (auto& p : pebble) p += shift;
  const Polyhedron far = ComputeConvexHull(pebble, "pebble");
  EXPECT_EQ(far.vertices_m.size(), 8u);
  for (const auto& v : far.vertices_m) EXPECT_LT((v - shift).cwiseAbs().maxCoeff(), 0.005 + 1e-9);
}

TEST(ComputeConvexHull, DenseSphereIsClosedOrientedAndQuiet) {
  std::mt19937_64 rng(2);
  const auto points = testing::EllipsoidSurface(1, 1, 1, 5000, rng);
  ::testing::internal::CaptureStdout();
  const Polyhedron hull = ComputeConvexHull(points, "sphere");
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");  // no qhull statistics
  EXPECT_EQ(hull.vertices_m.size(), 5000u);
  EXPECT_EQ(hull.triangles.size(), 2 * 5000u - 4);  // Euler: F = 2V - 4 for a triangulated sphere
  EXPECT_TRUE(IsClosedAndOriented(hull));
}

TEST(ComputeConvexHull, DegenerateInputIsAClearError) {
  EXPECT_NE(HullError({}).find("scan.xyz: 0 points; a rock needs at least 4"), std::string::npos);
  EXPECT_NE(HullError({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}).find("3 points"), std::string::npos);
  EXPECT_NE(HullError({{1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}}).find("coincide"),
            std::string::npos);
  std::vector<Eigen::Vector3d> line, plane;
  for (int i = 0; i < 50; ++i) {
    line.push_back(Eigen::Vector3d(1, 2, 3) * (0.1 * i));
    plane.emplace_back(0.1 * (i % 7), 0.3 * (i % 5), 0.1 * (i % 7) + 0.3 * (i % 5));  // z = x + y
  }
  EXPECT_NE(HullError(line).find("collinear"), std::string::npos) << HullError(line);
  EXPECT_NE(HullError(plane).find("coplanar"), std::string::npos) << HullError(plane);
  // Coordinates whose squares overflow are out of range, not "collinear".
  const std::string far = HullError({{0, 0, 0}, {1e300, 0, 0}, {0, 1e300, 0}, {0, 0, 1e300}});
  EXPECT_NE(far.find("point 2 ("), std::string::npos) << far;
  EXPECT_NE(far.find("coordinates out of range"), std::string::npos) << far;
  EXPECT_EQ(far.find("collinear"), std::string::npos) << far;
  // A thin but solid slab is fine.
  std::vector<Eigen::Vector3d> slab = testing::BoxCorners(1, 1, 1e-3);
  EXPECT_EQ(HullError(slab), "");
}

TEST(SpanningTetrahedron, SpansASolid) {
  std::mt19937_64 rng(3);
  const auto points = testing::EllipsoidSurface(3, 2, 1, 1000, rng);
  const auto t = SpanningTetrahedron(points, "ellipsoid");
  const double volume6 =
      std::abs((points[t[1]] - points[t[0]])
                   .dot((points[t[2]] - points[t[0]]).cross(points[t[3]] - points[t[0]])));
  // A large fraction of the ellipsoid's volume 8 pi: at least that of a thin sliver.
  EXPECT_GT(volume6 / 6, 1.0);
}

}  // namespace
}  // namespace talus::pointclouds
