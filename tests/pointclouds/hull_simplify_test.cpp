#include "pointclouds/hull_simplify.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "solver/shapes.hpp"
#include "test_clouds.hpp"

namespace talus::pointclouds {
namespace {

TEST(SimplifyHull, FewerVerticesCostMoreVolume) {
  const Polyhedron sphere = MakeIcosphere(1.0, 3);  // 642 vertices
  double previous_error = 1;
  for (int k : {12, 42, 162}) {
    SimplifyReport report;
    const Polyhedron simple = SimplifyHull(sphere, k, &report);
    EXPECT_TRUE(testing::IsClosedAndOriented(simple)) << k;
    EXPECT_LE(report.vertices_after, k);
    EXPECT_EQ(report.vertices_before, 642);
    // An inner approximation: volume lost, never gained; the error shrinks with k.
    EXPECT_GT(report.volume_error, 0) << k;
    EXPECT_LT(report.volume_error, previous_error) << k;
    EXPECT_GT(report.inertia_error, 0) << k;
    EXPECT_GT(report.max_distance_m, 0) << k;
    previous_error = report.volume_error;
    // Every vertex kept is a vertex of the original hull.
    for (const auto& v : simple.vertices_m)
      EXPECT_NE(std::find(sphere.vertices_m.begin(), sphere.vertices_m.end(), v),
                sphere.vertices_m.end());
  }
  // 162 well-spread vertices of a sphere hold its volume within 5 %.
  EXPECT_LT(previous_error, 0.05);
}

TEST(SimplifyHull, EnoughVerticesChangeNothing) {
  const Polyhedron box = MakeBox(3, 2, 1);
  SimplifyReport report;
  const Polyhedron same = SimplifyHull(box, 8, &report);
  EXPECT_EQ(same.vertices_m.size(), 8u);
  EXPECT_EQ(report.volume_error, 0);
  EXPECT_EQ(report.inertia_error, 0);
  // A bevelled box (24 vertices) down to 8: the greedy choice still keeps most of it.
  const Polyhedron eota = MakeBevelledBox(1, 1, 0.5, 0.1);
  const Polyhedron simple = SimplifyHull(eota, 8, &report);
  EXPECT_EQ(report.vertices_after, 8);
  EXPECT_LT(report.volume_error, 0.4);
  EXPECT_TRUE(testing::IsClosedAndOriented(simple));
}

}  // namespace
}  // namespace talus::pointclouds
