#include "solver/polyhedron.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/shapes.hpp"

namespace talus {
namespace {

TEST(MassProperties, BoxMatchesClosedForm) {
  // Solid box a x b x c: V = abc, I_xx = m (b^2 + c^2) / 12 etc. Tolerance: round-off.
  Polyhedron box = MakeBox(1, 2, 3);
  for (auto& v : box.vertices_m) v += Eigen::Vector3d(5, -7, 2);  // off the origin
  const MassProperties mp = ComputeMassProperties(box, 2000);
  const double m = 2000 * 6;
  EXPECT_NEAR(mp.volume_m3, 6, 1e-12);
  EXPECT_LT((mp.centroid_m - Eigen::Vector3d(5, -7, 2)).norm(), 1e-12);
  Eigen::Matrix3d expected = Eigen::Vector3d(m * 13 / 12, m * 10 / 12, m * 5 / 12).asDiagonal();
  EXPECT_LT((mp.inertia_kg_m2 - expected).norm(), 1e-9 * m);
}

TEST(MassProperties, OctahedronAndTetrahedronMatchClosedForms) {
  // Regular octahedron with vertices at distance h on the axes: V = 4 h^3 / 3, I = m h^2 / 5.
  const double h = 0.7;
  const MassProperties oct = ComputeMassProperties(MakeOctahedron(2 * h, 2 * h, 2 * h), 1.0);
  EXPECT_NEAR(oct.volume_m3, 4 * h * h * h / 3, 1e-14);
  EXPECT_NEAR(oct.inertia_kg_m2(0, 0), oct.volume_m3 * h * h / 5, 1e-14);
  // Corner tetrahedron (0, e_x, e_y, e_z): V = 1/6, centroid (1/4, 1/4, 1/4).
  Polyhedron tet;
  tet.vertices_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  const MassProperties t = ComputeMassProperties(tet, 1.0);
  EXPECT_NEAR(t.volume_m3, 1.0 / 6, 1e-15);
  EXPECT_LT((t.centroid_m - Eigen::Vector3d::Constant(0.25)).norm(), 1e-15);
  // About the centroid: I_xx = V (3/40) = 1/80 and the product of inertia -C_xy = 1/480 with
  // C_xy = int x y dV - V c_x c_y = 1/120 - 1/96 (Tonon 2004, J. Math. Stat. 1:8).
  EXPECT_NEAR(t.inertia_kg_m2(0, 0), 1.0 / 80, 1e-15);
  EXPECT_NEAR(t.inertia_kg_m2(0, 1), 1.0 / 480, 1e-15);
}

TEST(MassProperties, IcosphereAndCylinderConvergeToTheSmoothSolids) {
  // Inscribed polyhedra approach V = 4/3 pi r^3 and V = pi r^2 h from below.
  const double sphere = 4.0 / 3 * std::numbers::pi;
  EXPECT_NEAR(ComputeMassProperties(MakeIcosphere(1, 5), 1).volume_m3, sphere, 1e-3 * sphere);
  const MassProperties cyl = ComputeMassProperties(MakeCylinder(0.5, 0.2, 512), 1);
  const double v = std::numbers::pi * 0.25 * 0.2;
  EXPECT_NEAR(cyl.volume_m3, v, 1e-4 * v);
  EXPECT_NEAR(cyl.inertia_kg_m2(2, 2), 0.5 * v * 0.25, 1e-4 * v * 0.125);  // m r^2 / 2
}

TEST(BevelledBox, HasTwentyFourVerticesAndTheRequestedVolume) {
  const double bevel = BevelForVolume(0.93, 0.93, 0.47, 0.312);
  ASSERT_GT(bevel, 0);
  const Polyhedron eota = MakeBevelledBox(0.93, 0.93, 0.47, bevel);
  EXPECT_EQ(eota.vertices_m.size(), 24u);
  EXPECT_EQ(eota.triangles.size(), 2u * 24 - 4);  // closed convex triangulation: F = 2V - 4
  EXPECT_NEAR(ComputeMassProperties(eota, 1).volume_m3, 0.312, 1e-9);
  // Closed form: the box less 12 edge prisms (d^2/2 each per metre), plus the prisms' overlaps at
  // the 8 corners (3 pairs of d^3/3 less the triple overlap d^3/4), less the corner tetrahedra
  // cut by the triangles x + y + z = 2d (d^3/12): V = abc - 2 d^2 (a+b+c) + 16/3 d^3.
  const double a = 0.93, c = 0.47, d = bevel;
  EXPECT_NEAR(a * a * c - 2 * d * d * (a + a + c) + 16.0 / 3 * d * d * d, 0.312, 1e-9);
  EXPECT_LT(BevelForVolume(1, 1, 1, 2.0), 0);  // more than the box: not reachable
}

TEST(RockShape, PrincipalFrameIsRightHandedAndReproducesTheInput) {
  Polyhedron box = MakeBox(3, 1, 2);
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.3, -0.5, 0.2, 0.7).normalized();
  for (auto& v : box.vertices_m) v = q * v + Eigen::Vector3d(100, 200, 300);
  const RockShape rock = MakeRockShape(box, 2500);
  std::string why;
  EXPECT_TRUE(rock.IsValid(&why)) << why;
  EXPECT_NEAR(rock.mass_kg, 2500 * 6, 1e-12 * 2500 * 6);  // 300 m off the origin
  EXPECT_LE(rock.inertia_kg_m2(0), rock.inertia_kg_m2(1));
  EXPECT_LE(rock.inertia_kg_m2(1), rock.inertia_kg_m2(2));
  EXPECT_NEAR(rock.principal_to_input.toRotationMatrix().determinant(), 1.0, 1e-12);
  // Every hull vertex maps back onto an input vertex.
  for (const auto& b : rock.vertices_m) {
    const Eigen::Vector3d x = rock.centroid_input_m + rock.principal_to_input * b;
    double nearest = 1e9;
    for (const auto& v : box.vertices_m) nearest = std::min(nearest, (x - v).norm());
    EXPECT_LT(nearest, 1e-9);
  }
  // Minor axis (smallest moment) lies along the box's longest side (3 m, input x rotated by q).
  const Eigen::Vector3d minor = rock.principal_to_input * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::abs(minor.dot(q * Eigen::Vector3d::UnitX())), 1.0, 1e-9);
  EXPECT_NEAR(rock.bounding_radius_m, std::sqrt(1.5 * 1.5 + 0.5 * 0.5 + 1.0), 1e-12);
}

TEST(RockShape, NeighboursAreTheHullsEdges) {
  // A closed triangulated surface of genus 0 with V vertices has E = 3 V - 6 edges (Euler: V - E +
  // F = 2 and 2 E = 3 F); each edge is listed at both its ends, once, and is a side of a triangle.
  for (const Polyhedron& hull : {MakeBox(3, 1, 2), MakeEllipsoid(0.5, 0.4, 0.3, 2)}) {
    const RockShape rock = MakeRockShape(hull, 2500);
    const int vertex_count = static_cast<int>(rock.vertices_m.size());
    ASSERT_EQ(rock.neighbour_start.size(), rock.vertices_m.size() + 1);
    EXPECT_EQ(rock.neighbours.size(), 2 * (3 * rock.vertices_m.size() - 6));
    for (int a = 0; a < vertex_count; ++a) {
      for (int i = rock.neighbour_start[a]; i < rock.neighbour_start[a + 1]; ++i) {
        const int b = rock.neighbours[i];
        ASSERT_NE(a, b);
        if (i > rock.neighbour_start[a]) {
          EXPECT_LT(rock.neighbours[i - 1], b);
        }
        const auto begin = rock.neighbours.begin();
        EXPECT_TRUE(std::binary_search(begin + rock.neighbour_start[b],
                                       begin + rock.neighbour_start[b + 1], a));
        EXPECT_TRUE(std::any_of(rock.triangles.begin(), rock.triangles.end(), [&](const auto& t) {
          return std::count(t.begin(), t.end(), a) && std::count(t.begin(), t.end(), b);
        }));
      }
    }
  }
  EXPECT_EQ(MakeRockShape(MakeEllipsoid(0.5, 0.4, 0.3, 2), 2500).vertices_m.size(), 162u);
}

}  // namespace
}  // namespace talus
