// The built-in rock shapes (solver/shapes.hpp): each is a closed, consistently oriented convex
// mesh of the documented size, with the volume and inertia of its closed form. Complements
// polyhedron_test.cpp, which checks ComputeMassProperties on a box, a regular octahedron, fine
// icospheres and cylinders, and the EOTA bevel.

#include "solver/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>

namespace talus {
namespace {

constexpr double kPi = std::numbers::pi;

// A closed, consistently oriented, convex triangle mesh whose faces point outwards: every directed
// edge once and its reverse once (so V - E + F = 2 for a sphere-like mesh), no degenerate
// triangle, and every vertex on the inner side of every face's plane (to 1e-12 of the size).
void ExpectClosedConvexOutward(const Polyhedron& poly, const std::string& what) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : poly.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << what << ": edge " << edge.first << "-" << edge.second;
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u)
        << what << ": edge " << edge.first << "-" << edge.second << " has no twin";
  }
  const long v = static_cast<long>(UsedVertices(poly).size());
  const long e = static_cast<long>(directed.size()) / 2;
  const long f = static_cast<long>(poly.triangles.size());
  EXPECT_EQ(v - e + f, 2) << what;
  double size = 0;
  for (const auto& p : poly.vertices_m) size = std::max(size, p.norm());
  for (const auto& t : poly.triangles) {
    const Eigen::Vector3d &a = poly.vertices_m[t[0]], &b = poly.vertices_m[t[1]],
                          &c = poly.vertices_m[t[2]];
    const Eigen::Vector3d normal = (b - a).cross(c - a);
    ASSERT_GT(normal.norm(), 1e-12 * size * size) << what << ": degenerate triangle";
    const Eigen::Vector3d unit = normal.normalized();
    EXPECT_GT(unit.dot(a), 0) << what << ": a face points inwards (the shape is centred)";
    for (const auto& p : poly.vertices_m)
      EXPECT_LE(unit.dot(p - a), 1e-12 * size) << what << ": not convex";
  }
}

// Extents of the vertices along x, y, z.
Eigen::Vector3d Extents(const Polyhedron& poly) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& p : poly.vertices_m) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return hi - lo;
}

TEST(Shapes, EveryBuiltInIsAClosedConvexOutwardMeshCentredAtTheOrigin) {
  const std::pair<const char*, Polyhedron> shapes[] = {
      {"box", MakeBox(1.2, 0.7, 0.4)},
      {"octahedron", MakeOctahedron(1.0, 0.6, 0.3)},
      {"icosphere 0", MakeIcosphere(0.5, 0)},
      {"icosphere 2", MakeIcosphere(0.5, 2)},
      {"ellipsoid", MakeEllipsoid(2.0, 1.0, 0.5, 2)},
      {"cylinder 3", MakeCylinder(0.3, 1.0, 3)},
      {"cylinder 17", MakeCylinder(0.3, 0.2, 17)},
      {"bevelled box", MakeBevelledBox(0.93, 0.93, 0.47, 0.05)},
  };
  for (const auto& [name, poly] : shapes) {
    ExpectClosedConvexOutward(poly, name);
    const MassProperties mp = ComputeMassProperties(poly, 1.0);
    EXPECT_GT(mp.volume_m3, 0) << name;
    // Every shape is symmetric about its centre: centroid at the origin, no products of inertia
    // along x, y, z (the cylinder's polygon of 3 or 17 sides has I_xx = I_yy, also no product).
    EXPECT_LT(mp.centroid_m.norm(), 1e-12) << name;
    const Eigen::Matrix3d off =
        mp.inertia_kg_m2 - Eigen::Matrix3d(mp.inertia_kg_m2.diagonal().asDiagonal());
    EXPECT_LT(off.norm(), 1e-12 * mp.inertia_kg_m2.norm()) << name;
  }
}

// The documented vertex counts: a box 8 (12 triangles), a bevelled box 24 (44), an icosphere
// 10 * 4^s + 2 (20 * 4^s triangles), a cylinder 2 n (4 n - 4), an octahedron 6 (8); and sizes: the
// box, octahedron and cylinder span exactly their dimensions, icosphere vertices lie on the sphere.
TEST(Shapes, VertexCountsAndExtentsAreTheDocumentedOnes) {
  EXPECT_EQ(MakeBox(1, 2, 3).vertices_m.size(), 8u);
  EXPECT_EQ(MakeBox(1, 2, 3).triangles.size(), 12u);
  EXPECT_EQ(MakeBevelledBox(1, 2, 3, 0.1).triangles.size(), 44u);
  EXPECT_EQ(MakeOctahedron(1, 2, 3).vertices_m.size(), 6u);
  EXPECT_EQ(MakeOctahedron(1, 2, 3).triangles.size(), 8u);
  for (int s = 0; s <= 3; ++s) {
    const Polyhedron ico = MakeIcosphere(2.5, s);
    const std::size_t power = std::size_t{1} << (2 * s);
    EXPECT_EQ(ico.vertices_m.size(), 10 * power + 2) << s;
    EXPECT_EQ(ico.triangles.size(), 20 * power) << s;
    for (const auto& p : ico.vertices_m) EXPECT_NEAR(p.norm(), 2.5, 1e-14) << s;
  }
  for (int n : {3, 8, 33}) {
    const Polyhedron cyl = MakeCylinder(0.4, 1.5, n);
    EXPECT_EQ(cyl.vertices_m.size(), 2u * n) << n;
    EXPECT_EQ(cyl.triangles.size(), 4u * n - 4) << n;
    for (const auto& p : cyl.vertices_m) {
      EXPECT_NEAR(p.head<2>().norm(), 0.4, 1e-15) << n;
      EXPECT_NEAR(std::abs(p.z()), 0.75, 1e-15) << n;
    }
  }
  EXPECT_LT((Extents(MakeBox(1.2, 0.7, 0.4)) - Eigen::Vector3d(1.2, 0.7, 0.4)).norm(), 1e-15);
  EXPECT_LT((Extents(MakeBevelledBox(1.2, 0.7, 0.4, 0.1)) - Eigen::Vector3d(1.2, 0.7, 0.4)).norm(),
            1e-15);
  EXPECT_LT((Extents(MakeOctahedron(1.0, 0.6, 0.3)) - Eigen::Vector3d(1.0, 0.6, 0.3)).norm(),
            1e-15);
  // From one subdivision on, the icosphere has vertices on the axes: the ellipsoid spans a, b, c.
  EXPECT_LT((Extents(MakeEllipsoid(2.0, 1.0, 0.5, 1)) - Eigen::Vector3d(2.0, 1.0, 0.5)).norm(),
            1e-14);
}

// Regular icosahedron (subdivisions 0) of circumradius R: edge s = R / sin(2 pi / 5),
// V = 5 (3 + sqrt 5) s^3 / 12, I = m phi^2 s^2 / 10 about any axis through the centre (phi the
// golden ratio). Tolerance: round-off (1e-12 relative).
TEST(Shapes, IcosahedronMatchesTheClosedForm) {
  const double r = 0.8, rho = 2650;
  const double s = r / std::sin(2 * kPi / 5);
  const double phi = (1 + std::sqrt(5.0)) / 2;
  const double volume = 5 * (3 + std::sqrt(5.0)) * s * s * s / 12;
  const MassProperties mp = ComputeMassProperties(MakeIcosphere(r, 0), rho);
  EXPECT_NEAR(mp.volume_m3, volume, 1e-12 * volume);
  const double moment = rho * volume * phi * phi * s * s / 10;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mp.inertia_kg_m2(k, k), moment, 1e-12 * moment) << k;
}

// An ellipsoid is the unit icosphere scaled by (a/2, b/2, c/2): V scales by abc / 8 exactly, and
// since an icosphere's second moments are isotropic (icosahedral symmetry), int x^2 dV = S for
// each axis on the unit icosphere and I_xx = rho (abc / 8) S ((b/2)^2 + (c/2)^2). The subdivided
// solid approaches pi abc / 6 from below (an inscribed polyhedron), its shortfall falling about
// fourfold per subdivision (3.4 % at 2, 0.86 % at 3): within 1 % at 3 subdivisions.
TEST(Shapes, EllipsoidIsTheScaledIcosphere) {
  const double a = 1.6, b = 1.0, c = 0.6, rho = 2000;
  for (int subdivisions : {1, 3}) {
    const MassProperties unit = ComputeMassProperties(MakeIcosphere(1.0, subdivisions), 1.0);
    const double second = unit.inertia_kg_m2(0, 0) / 2;  // S = I_xx / 2 for unit density
    const MassProperties e = ComputeMassProperties(MakeEllipsoid(a, b, c, subdivisions), rho);
    const double scale = a * b * c / 8;
    EXPECT_NEAR(e.volume_m3, unit.volume_m3 * scale, 1e-12);
    const Eigen::Vector3d half(a / 2, b / 2, c / 2);
    for (int k = 0; k < 3; ++k) {
      const double expected = rho * scale * second *
                              (half.squaredNorm() - half(k) * half(k));
      EXPECT_NEAR(e.inertia_kg_m2(k, k), expected, 1e-11 * expected) << subdivisions << ", " << k;
    }
    const double smooth = kPi * a * b * c / 6;
    EXPECT_LT(e.volume_m3, smooth);
    if (subdivisions == 3) {
      EXPECT_GT(e.volume_m3, 0.99 * smooth);
    }
  }
}

// Octahedron of extents a, b, c: eight tetrahedra (a/2)(b/2)(c/2)/6, V = abc / 6, and the
// regular octahedron's I = m h^2 / 5 scaled per axis: I_xx = m (b^2 + c^2) / 40.
TEST(Shapes, OctahedronOfUnequalExtentsMatchesTheClosedForm) {
  const double a = 1.3, b = 0.9, c = 0.5, rho = 2500;
  const MassProperties mp = ComputeMassProperties(MakeOctahedron(a, b, c), rho);
  const double volume = a * b * c / 6, m = rho * volume;
  EXPECT_NEAR(mp.volume_m3, volume, 1e-14);
  const Eigen::Vector3d expected(m * (b * b + c * c) / 40, m * (a * a + c * c) / 40,
                                 m * (a * a + b * b) / 40);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(mp.inertia_kg_m2(k, k), expected(k), 1e-12 * expected(k)) << k;
}

// Prism over a regular n-gon of circumradius R, height h: V = (n/2) R^2 sin(2 pi / n) h, and
// with the polygon's polar moment J = A R^2 (2 + cos(2 pi / n)) / 6 (a triangle: A R^2 / 4, a
// square: A R^2 / 3, the circle's A R^2 / 2 as n grows), I_zz = m R^2 (2 + cos(2 pi / n)) / 6 and
// I_xx = I_yy = I_zz / 2 + m h^2 / 12. Exact for every n: round-off tolerance.
TEST(Shapes, CylinderIsThePrismOverTheRegularPolygon) {
  const double r = 0.35, h = 0.8, rho = 2700;
  for (int n : {3, 4, 6, 25}) {
    const MassProperties mp = ComputeMassProperties(MakeCylinder(r, h, n), rho);
    const double volume = 0.5 * n * r * r * std::sin(2 * kPi / n) * h, m = rho * volume;
    EXPECT_NEAR(mp.volume_m3, volume, 1e-14) << n;
    const double izz = m * r * r * (2 + std::cos(2 * kPi / n)) / 6;
    EXPECT_NEAR(mp.inertia_kg_m2(2, 2), izz, 1e-12 * izz) << n;
    const double ixx = izz / 2 + m * h * h / 12;
    EXPECT_NEAR(mp.inertia_kg_m2(0, 0), ixx, 1e-12 * ixx) << n;
    EXPECT_NEAR(mp.inertia_kg_m2(1, 1), ixx, 1e-12 * ixx) << n;
  }
}

// A box is a bevelled box without bevel, and the bevelled box of bevel d has the volume
// abc - 2 d^2 (a + b + c) + 16 d^3 / 3 (polyhedron_test.cpp derives it) for every d up to half
// the smallest side; BevelForVolume inverts it to 1e-9 m, gives 0 for the box's own volume (to
// 1e-8 m: dV/dd = 0 at d = 0, so round-off in V hides a bevel below sqrt(eps / 6) = 6e-9 m), and
// -1 below the deepest bevel's volume (for a unit cube, 1 - 3/2 + 2/3 = 1/6 m^3).
TEST(Shapes, BevelledBoxVolumeFollowsItsClosedFormAndBevelForVolumeInvertsIt) {
  const Polyhedron box = MakeBox(0.9, 0.6, 0.5), plain = MakeBevelledBox(0.9, 0.6, 0.5, 0.0);
  EXPECT_EQ(box.vertices_m, plain.vertices_m);
  EXPECT_EQ(box.triangles, plain.triangles);
  const double a = 0.9, b = 0.6, c = 0.5;
  for (double d : {0.01, 0.1, 0.2, 0.24}) {
    const double volume = a * b * c - 2 * d * d * (a + b + c) + 16 * d * d * d / 3;
    EXPECT_NEAR(ComputeMassProperties(MakeBevelledBox(a, b, c, d), 1).volume_m3, volume, 1e-14)
        << d;
    EXPECT_NEAR(BevelForVolume(a, b, c, volume), d, 1e-9) << d;
  }
  EXPECT_NEAR(BevelForVolume(1, 1, 1, 1.0), 0.0, 1e-8);
  EXPECT_LT(BevelForVolume(1, 1, 1, 1.0 / 6 - 1e-3), 0);
  EXPECT_GT(BevelForVolume(1, 1, 1, 1.0 / 6 + 1e-3), 0.45);
}

}  // namespace
}  // namespace talus
