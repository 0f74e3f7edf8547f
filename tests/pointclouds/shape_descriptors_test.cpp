#include "pointclouds/shape_descriptors.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/shapes.hpp"
#include "test_clouds.hpp"

namespace talus::pointclouds {
namespace {

Polyhedron Rotated(Polyhedron poly, const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  for (auto& v : poly.vertices_m) v = r * v + t;
  return poly;
}

TEST(ClassifyZingg, FourClassesAroundTwoThirds) {
  EXPECT_EQ(ClassifyZingg(0.9, 0.9), ShapeClass::kEquant);
  EXPECT_EQ(ClassifyZingg(0.9, 0.5), ShapeClass::kPlaty);
  EXPECT_EQ(ClassifyZingg(0.5, 0.9), ShapeClass::kElongated);
  EXPECT_EQ(ClassifyZingg(0.5, 0.5), ShapeClass::kBladed);
  EXPECT_STREQ(ShapeClassName(ShapeClass::kPlaty), "platy");
}

TEST(DescribeShape, BoxDimensionsAndWadellSphericity) {
  const ShapeDescriptors box = DescribeShape(MakeBox(1, 4, 2));
  EXPECT_NEAR((box.dimensions_m - Eigen::Vector3d(4, 2, 1)).norm(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(box.b_over_a, 0.5);
  EXPECT_DOUBLE_EQ(box.c_over_b, 0.5);
  EXPECT_EQ(box.shape_class, ShapeClass::kBladed);
  EXPECT_NEAR(box.surface_area_m2, 2 * (4 + 2 + 8), 1e-12);
  // Cube: psi = pi^(1/3) 6^(2/3) / 6 = (pi / 6)^(1/3) = 0.80600 (Wadell 1935).
  const ShapeDescriptors cube = DescribeShape(MakeBox(2, 2, 2));
  EXPECT_NEAR(cube.sphericity, std::cbrt(std::numbers::pi / 6), 1e-12);
  EXPECT_EQ(cube.shape_class, ShapeClass::kEquant);
  EXPECT_EQ(DescribeShape(MakeBox(1, 0.3, 0.3)).shape_class, ShapeClass::kElongated);
}

TEST(DescribeShape, PlatyEotaBlockInAnyOrientation) {
  // Equal moments about x and y leave the principal axes free in that plane; the dimensions
  // must not depend on them.
  const Polyhedron eota = MakeBevelledBox(0.93, 0.93, 0.47, 0.08);
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 5; ++trial) {
    const ShapeDescriptors s =
        DescribeShape(Rotated(eota, testing::RandomRotation(rng), Eigen::Vector3d(100, -50, 7)));
    EXPECT_NEAR((s.dimensions_m - Eigen::Vector3d(0.93, 0.93, 0.47)).norm(), 0, 1e-9);
    EXPECT_EQ(s.shape_class, ShapeClass::kPlaty);
  }
}

TEST(DescribeShape, RoundShapes) {
  // Icosphere of 2562 vertices: sphericity within 0.5 % of 1.
  const ShapeDescriptors sphere = DescribeShape(MakeIcosphere(1.0, 4));
  EXPECT_GT(sphere.sphericity, 0.995);
  EXPECT_LE(sphere.sphericity, 1.0);
  // A disk of 24 segments: across flats cos(pi/24) = 0.9914 of the diameter.
  const ShapeDescriptors disk = DescribeShape(MakeCylinder(0.5, 0.2, 24));
  EXPECT_NEAR(disk.dimensions_m.x(), 1.0, 0.01);
  EXPECT_NEAR(disk.dimensions_m.y(), 1.0, 0.01);
  EXPECT_NEAR(disk.dimensions_m.z(), 0.2, 1e-12);
  EXPECT_EQ(disk.shape_class, ShapeClass::kPlaty);
  // Ellipsoid 3 x 2 x 1 (642 vertices): within 1 % of its axes.
  const ShapeDescriptors ellipsoid = DescribeShape(MakeEllipsoid(3, 2, 1, 3));
  EXPECT_NEAR(ellipsoid.dimensions_m.x(), 3, 0.03);
  EXPECT_NEAR(ellipsoid.dimensions_m.y(), 2, 0.02);
  EXPECT_NEAR(ellipsoid.dimensions_m.z(), 1, 0.01);
}

}  // namespace
}  // namespace talus::pointclouds
