#include "pointclouds/builtin_shapes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <tuple>
#include <vector>

#include "common/error.hpp"

namespace talus::pointclouds {
namespace {

Eigen::Vector3d Extent(const Polyhedron& poly) {
  Eigen::Vector3d lo = poly.vertices_m[0], hi = lo;
  for (const auto& v : poly.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return hi - lo;
}

BuiltinSpec Spec(const std::string& name, const std::vector<double>& dimensions_m) {
  BuiltinSpec spec;
  spec.name = name;
  spec.dimensions_m = dimensions_m;
  return spec;
}

double Volume(const Polyhedron& poly) { return ComputeMassProperties(poly, 1.0).volume_m3; }

BuiltinSpec RockSpecOf(std::uint64_t seed, int points = 32, double roughness = 0.15) {
  BuiltinSpec spec = Spec("rock", {0.46, 0.30, 0.20});
  spec.points = points;
  spec.roughness = roughness;
  spec.shape_seed = seed;
  return spec;
}

TEST(BuiltinSpec, EveryNameWithItsDimensionsIsValid) {
  std::string why;
  for (const auto& [name, dims] :
       std::vector<std::pair<std::string, std::vector<double>>>{{"box", {1, 2, 3}},
                                                                {"box", {1}},
                                                                {"ellipsoid", {3, 2, 1}},
                                                                {"icosphere", {}},
                                                                {"cylinder", {1, 2}},
                                                                {"disk", {1, 0.2}},
                                                                {"rock", {0.46, 0.30, 0.20}},
                                                                {"rock", {0.5}},
                                                                {"eota111", {}},
                                                                {"eota221", {0.93, 0.93, 0.47}}}) {
    const BuiltinSpec spec = Spec(name, dims);
    EXPECT_TRUE(spec.IsValid(&why)) << name << ": " << why;
    EXPECT_GE(MakeBuiltinShape(spec).vertices_m.size(), 8u) << name;
  }
  EXPECT_FALSE(Spec("boulder", {1}).IsValid(&why));
  EXPECT_NE(why.find("unknown built-in shape 'boulder'; expected one of box"), std::string::npos)
      << why;
  EXPECT_FALSE(Spec("cylinder", {1}).IsValid(&why));
  EXPECT_NE(why.find("diameter, height"), std::string::npos) << why;
  EXPECT_FALSE(Spec("box", {1, -2, 3}).IsValid(&why));
  EXPECT_NE(why.find("positive"), std::string::npos) << why;
  EXPECT_THROW(MakeBuiltinShape(Spec("box", {})), InputError);
}

TEST(MakeBuiltinShape, DimensionsAlongXyz) {
  EXPECT_NEAR((Extent(MakeBuiltinShape(Spec("box", {1, 2, 3}))) - Eigen::Vector3d(1, 2, 3)).norm(),
              0, 1e-15);
  EXPECT_NEAR(
      (Extent(MakeBuiltinShape(Spec("ellipsoid", {3, 2, 1}))) - Eigen::Vector3d(3, 2, 1)).norm(), 0,
      1e-12);
  EXPECT_NEAR(
      (Extent(MakeBuiltinShape(Spec("cylinder", {1, 2}))) - Eigen::Vector3d(1, 1, 2)).norm(), 0,
      1e-12);
  EXPECT_NEAR(Extent(MakeBuiltinShape(Spec("icosphere", {}))).z(), 1, 1e-12);
}

TEST(MakeBuiltinShape, EotaStandardBlocksAreOneCubicMetre) {
  // EOTA test blocks (ETAG 027 / EAD 340059): EOTA111 bounding box 1.122 m, EOTA221 1.414 x 1.414 x
  // 0.707 m, each for 1 m^3; the bevel is chosen so that the volume matches.
  const Polyhedron e111 = MakeBuiltinShape(Spec("eota111", {}));
  EXPECT_NEAR(Volume(e111), 1.0, 1e-9);
  EXPECT_NEAR((Extent(e111) - Eigen::Vector3d::Constant(1.122)).norm(), 0, 1e-12);
  EXPECT_EQ(e111.vertices_m.size(), 24u);
  const Polyhedron e221 = MakeBuiltinShape(Spec("eota221", {}));
  EXPECT_NEAR(Volume(e221), 1.0, 1e-9);
  EXPECT_NEAR((Extent(e221) - Eigen::Vector3d(1.414, 1.414, 0.707)).norm(), 0, 1e-12);

  // Scaled to a volume: same proportions.
  BuiltinSpec big = Spec("eota221", {});
  big.volume_m3 = 8.0;
  EXPECT_NEAR(Volume(MakeBuiltinShape(big)), 8.0, 1e-8);
  EXPECT_NEAR(Extent(MakeBuiltinShape(big)).x(), 2 * 1.414, 1e-12);

  // Given dimensions keep the standard bevel ratio, or take the bevel a volume needs.
  const Polyhedron half = MakeBuiltinShape(Spec("eota111", {0.561}));
  EXPECT_NEAR(Volume(half), 0.125, 1e-9);
  BuiltinSpec chant_sura = Spec("eota221", {0.93, 0.93, 0.47});
  chant_sura.volume_m3 = 780.0 / 2500;
  std::string what;
  EXPECT_NEAR(Volume(MakeBuiltinShape(chant_sura, &what)), 0.312, 1e-9);
  EXPECT_NE(what.find("eota221 0.93 x 0.93 x 0.47 m, bevel"), std::string::npos) << what;
  chant_sura.volume_m3 = 0.5;  // more than the box holds
  EXPECT_THROW(MakeBuiltinShape(chant_sura), InputError);
}

// The rock's bounding box is exactly a x b x c by construction (the hull is rescaled per axis):
// only rounding remains, a few ulps of 0.46 m (1e-16), checked at 1e-12. Every draw is a solid:
// a closed convex hull with positive mass properties and at least 1 % of the ellipsoid's volume
// (the redraw guard), with at most `points` vertices. 4 points exercise the guard (about 4 % of
// 4-point draws are redrawn).
TEST(MakeBuiltinShape, RockBoundingBoxIsItsDimensionsForEverySeed) {
  const Eigen::Vector3d size(0.46, 0.30, 0.20);
  const double ellipsoid_m3 = std::numbers::pi / 6 * size.prod();
  double worst_extent = 0, smallest_fraction = 1;
  for (int points : {4, 5, 8, 32, 200})
    for (std::uint64_t seed = 0; seed < 200; ++seed) {
      const Polyhedron rock = MakeBuiltinShape(RockSpecOf(seed, points, seed % 3 * 0.25));
      worst_extent = std::max(worst_extent, (Extent(rock) - size).cwiseAbs().maxCoeff());
      EXPECT_GE(rock.vertices_m.size(), 4u);
      EXPECT_LE(rock.vertices_m.size(), static_cast<std::size_t>(points));
      const MassProperties mp = ComputeMassProperties(rock, 2700);
      EXPECT_GT(mp.inertia_kg_m2.determinant(), 0) << seed;
      smallest_fraction = std::min(smallest_fraction, mp.volume_m3 / ellipsoid_m3);
      const RockShape shape = MakeRockShape(rock, 2700);
      std::string why;
      EXPECT_TRUE(shape.IsValid(&why)) << "points " << points << ", seed " << seed << ": " << why;
    }
  std::printf("rock: worst bounding-box error %.2e m, smallest volume / ellipsoid %.4f\n",
              worst_extent, smallest_fraction);
  EXPECT_LT(worst_extent, 1e-12);
  EXPECT_GE(smallest_fraction, 0.01);
}

TEST(MakeBuiltinShape, RockIsAFunctionOfItsSeed) {
  const Polyhedron once = MakeBuiltinShape(RockSpecOf(7));
  const Polyhedron again = MakeBuiltinShape(RockSpecOf(7));
  ASSERT_EQ(once.vertices_m.size(), again.vertices_m.size());
  for (std::size_t k = 0; k < once.vertices_m.size(); ++k)
    for (int i = 0; i < 3; ++i) EXPECT_EQ(once.vertices_m[k][i], again.vertices_m[k][i]);  // bits
  EXPECT_EQ(once.triangles, again.triangles);

  // Other seeds, other rocks: no two of 50 volumes agree to 1e-9.
  std::vector<double> volumes;
  for (std::uint64_t seed = 0; seed < 50; ++seed)
    volumes.push_back(Volume(MakeBuiltinShape(RockSpecOf(seed))));
  std::sort(volumes.begin(), volumes.end());
  for (std::size_t k = 1; k < volumes.size(); ++k)
    EXPECT_GT(volumes[k] - volumes[k - 1], 1e-9 * volumes[k]);

  // The stream is pinned: this value changes only if the way points are drawn changes, which
  // changes every rock of every scene that names a shape_seed. The points use only +, *, / and
  // sqrt of mt19937_64 draws, so they are the same on every IEEE 754 platform; the tolerance
  // (1e-12 relative) leaves room only for another order of the hull's triangles in the volume sum.
  std::string what;
  const double volume = Volume(MakeBuiltinShape(RockSpecOf(7), &what));
  std::printf("rock seed 7: %zu vertices, volume %.17g m^3\n", once.vertices_m.size(), volume);
  EXPECT_EQ(once.vertices_m.size(), 25u);
  EXPECT_NEAR(volume, 0.0086948149309584444, 1e-12 * volume);
  EXPECT_EQ(what, "rock 0.46 x 0.3 x 0.2 m, 32 points, roughness 0.15, seed 7");
}

// Points on the ellipsoid itself (roughness 0): the hull is an inscribed polytope whose volume
// approaches the ellipsoid's, pi/6 abc, from below. The points are the affine image of n points
// uniform on the unit sphere, and volume ratios are affine-invariant, so the sphere's closed form
// holds: E[V(hull)] / V(ball) = (n-1)(n-2)(n-3) / ((n+1)(n+2)(n+3)) (Buchta, Mueller and Tichy
// 1985, "Stochastical approximation of convex bodies", Math. Ann. 271), a deficit of 12/n to first
// order. The rescale to the bounding box then stretches each axis by 2 / (2 - h_top - h_bottom),
// h the gap between the outermost point and the pole; a coordinate of a uniform point on the sphere
// is uniform on [-1, 1] (Archimedes), so E[h] = 2 / (n + 1) and the volume grows by 6/n to first
// order: the expected deficit is 6/n. The test takes the mean of n * deficit over 10 seeds, with
// a tolerance of 3: the spread of one draw is 2.5/n (sd of n * deficit measured with SciPy's
// Qhull over 100 draws of 2000 points, an implementation independent of this one), so the mean of
// 10 has a standard error of 0.8 and 3 is 3.8 standard errors. The hull never leaves the
// ellipsoid (checked).
TEST(MakeBuiltinShape, SmoothRockApproachesTheEllipsoid) {
  const double exact = std::numbers::pi / 6 * 0.46 * 0.30 * 0.20;
  for (int points : {200, 2000}) {
    double mean = 0, excess = 0;
    for (std::uint64_t seed = 0; seed < 10; ++seed) {
      const double error =
          (Volume(MakeBuiltinShape(RockSpecOf(seed, points, 0.0))) - exact) / exact;
      mean += -error / 10;
      excess = std::max(excess, error);
    }
    std::printf("smooth rock, %4d points: mean relative volume deficit %.3e (n x deficit %.2f; "
                "expected 6), largest excess %.2e\n",
                points, mean, points * mean, excess);
    EXPECT_EQ(excess, 0) << points;  // always inside
    EXPECT_NEAR(points * mean, 6.0, 3.0) << points;
  }
}

TEST(BuiltinSpec, RockKnobsAreChecked) {
  std::string why;
  EXPECT_TRUE(RockSpecOf(0).IsValid(&why)) << why;
  EXPECT_TRUE(RockSpecOf(0, 4, 0.0).IsValid(&why)) << why;
  EXPECT_TRUE(RockSpecOf(0, 4, 0.5).IsValid(&why)) << why;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [points, roughness, message] : std::vector<std::tuple<int, double, std::string>>{
           {3, 0.15, "points = 3 violates 4 <= points <= 10^6"},
           {-1, 0.15, "points = -1 violates"},
           {2000000, 0.15, "points = 2000000 violates"},
           {32, -0.01, "roughness = -0.01 violates 0 <= roughness <= 0.5"},
           {32, 0.6, "roughness = 0.6 violates"},
           {32, nan, "roughness = nan violates"},
           {32, inf, "roughness = inf violates"}}) {
    const BuiltinSpec spec = RockSpecOf(0, points, roughness);
    EXPECT_FALSE(spec.IsValid(&why)) << message;
    EXPECT_NE(why.find(message), std::string::npos) << why;
    EXPECT_THROW(MakeBuiltinShape(spec), InputError);
  }
  EXPECT_FALSE(Spec("rock", {1, 2}).IsValid(&why));
  EXPECT_NE(why.find("rock takes 1 or 3 dimensions"), std::string::npos) << why;
}

}  // namespace
}  // namespace talus::pointclouds
