#include "pointclouds/rock_source.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>

#include "common/error.hpp"
#include "scenes/scenes.hpp"
#include "test_clouds.hpp"
#include "tests/portable_random.hpp"

namespace talus::pointclouds {
namespace {

using testing::TempDir;
constexpr double kPi = std::numbers::pi;

RockSpec FileSpec(const std::string& file, double density_kg_m3 = 1000) {
  RockSpec spec;
  spec.file = file;
  spec.density_kg_m3 = density_kg_m3;
  return spec;
}

PointCloud Cloud(std::vector<Eigen::Vector3d> points, const std::string& source = "synthetic") {
  PointCloud cloud;
  cloud.source = source;
  cloud.points_m = std::move(points);
  return cloud;
}

double RelativeError(double value, double exact) {
  return std::abs(value - exact) / std::abs(exact);
}

// Relative error of the principal moments against exact ones (ascending).
double MomentError(const RockReport& r, const Eigen::Vector3d& exact) {
  return ((r.principal_moments_kg_m2 - exact).array().abs() / exact.array()).maxCoeff();
}

// The message of the InputError that MakeRock throws for `spec` ("" when it succeeds).
std::string RockError(const RockSpec& spec) {
  try {
    MakeRock(spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RockSpec, DefaultsWithASourceAreValid) {
  std::string why;
  RockSpec spec;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("needs a point cloud file or a built-in shape"), std::string::npos) << why;
  spec.builtin = "eota221";
  EXPECT_TRUE(spec.IsValid(&why)) << why;
  spec.file = "rock.ply";
  EXPECT_FALSE(spec.IsValid(&why));
  spec.file.clear();
  spec.volume_m3 = 1.0;
  spec.mass_kg = 2700;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("not both"), std::string::npos) << why;
  spec.mass_kg.reset();
  spec.density_kg_m3 = 0;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("density_kg_m3 = 0"), std::string::npos) << why;
  spec.density_kg_m3 = 2700;
  spec.max_vertices = 3;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("max_vertices = 3"), std::string::npos) << why;
  spec.max_vertices = 0;
  spec.builtin = "box";
  EXPECT_FALSE(spec.IsValid(&why));  // a box needs its dimensions
  EXPECT_NE(why.find("box takes 1 or 3 dimensions"), std::string::npos) << why;
}

// Closed forms: the point cloud's hull, integrated exactly, against textbook mass properties.
TEST(MakeRock, BoxAndCubeFromScans) {
  // Solid box a x b x c: V = abc, I_x = m (b^2 + c^2) / 12 (e.g. Goldstein, Classical Mechanics).
  std::mt19937_64 rng(11);
  for (const Eigen::Vector3d& d : {Eigen::Vector3d(0.5, 1.2, 2.0), Eigen::Vector3d(1, 1, 1)}) {
    auto points = testing::BoxInterior(d.x(), d.y(), d.z(), 2000, rng);
    for (const auto& c : testing::BoxCorners(d.x(), d.y(), d.z())) points.push_back(c);
    for (auto& p : points) p += Eigen::Vector3d(5, -3, 2);
    RockReport r;
    const RockShape rock = MakeRockFromPoints(Cloud(points), FileSpec("", 2500), &r);
    const double m = 2500 * d.prod();
    EXPECT_NEAR(r.volume_m3, d.prod(), 1e-12 * d.prod());
    EXPECT_NEAR(rock.mass_kg, m, 1e-9 * m);
    EXPECT_NEAR((r.centroid_m - Eigen::Vector3d(5, -3, 2)).norm(), 0, 1e-12);
    Eigen::Vector3d exact(m * (d.y() * d.y() + d.z() * d.z()) / 12,
                          m * (d.x() * d.x() + d.z() * d.z()) / 12,
                          m * (d.x() * d.x() + d.y() * d.y()) / 12);
    std::sort(exact.data(), exact.data() + 3);
    EXPECT_LT(MomentError(r, exact), 1e-12);
    EXPECT_EQ(r.hull_vertices, 8);
    EXPECT_EQ(r.hull_faces, 12);
    EXPECT_EQ(r.points_read, 2008u);
    Eigen::Vector3d sides = d;
    std::sort(sides.data(), sides.data() + 3, std::greater<>());
    EXPECT_NEAR((r.shape.dimensions_m - sides).norm(), 0, 1e-12);
  }
}

TEST(MakeRock, TetrahedraFromScans) {
  // Regular tetrahedron of edge L: V = L^3 / (6 sqrt 2), I = m L^2 / 20 about every axis through
  // the centroid (Tonon 2004, J. Math. Stat. 1:8).
  const double s =
      0.8;  // vertices (+-s, +-s, +-s) with an even number of minus signs: L = 2 sqrt2 s
  const std::vector<Eigen::Vector3d> regular = {{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}};
  RockReport r;
  MakeRockFromPoints(Cloud(regular), FileSpec(""), &r);
  const double L = 2 * std::sqrt(2.0) * s, V = L * L * L / (6 * std::sqrt(2.0)), m = 1000 * V;
  EXPECT_NEAR(r.volume_m3, V, 1e-14);
  EXPECT_LT(MomentError(r, Eigen::Vector3d::Constant(m * L * L / 20)), 1e-12);

  // Corner tetrahedron (0, a e1, b e2, c e3): V = abc/6, centroid (a, b, c)/4, central inertia
  // I_xx = 3m (b^2 + c^2)/80, I_xy = +m ab/80 (Tonon 2004, from E[x x'] = (sum v v' + s s')/20).
  const double a = 1.0, b = 2.0, c = 3.0;
  MakeRockFromPoints(Cloud({{0, 0, 0}, {a, 0, 0}, {0, b, 0}, {0, 0, c}}), FileSpec(""), &r);
  const double mc = 1000 * a * b * c / 6;
  EXPECT_NEAR(r.volume_m3, a * b * c / 6, 1e-14);
  EXPECT_NEAR((r.centroid_m - Eigen::Vector3d(a, b, c) / 4).norm(), 0, 1e-14);
  Eigen::Matrix3d exact;
  exact << 3 * (b * b + c * c), a * b, a * c, a * b, 3 * (a * a + c * c), b * c, a * c, b * c,
      3 * (a * a + b * b);
  exact *= mc / 80;
  EXPECT_LT((r.inertia_kg_m2 - exact).norm(), 1e-12 * exact.norm());
}

TEST(MakeRock, OctahedronFromScan) {
  // Octahedron |x|/a + |y|/b + |z|/c <= 1: V = 4abc/3, I_x = m (b^2 + c^2)/10 (E[x^2] = a^2/10
  // over the cross-polytope).
  const double a = 1.5, b = 1.0, c = 0.5;
  std::vector<Eigen::Vector3d> points = {{a, 0, 0},  {-a, 0, 0}, {0, b, 0},
                                         {0, -b, 0}, {0, 0, c},  {0, 0, -c}};
  std::mt19937_64 rng(12);
  for (const auto& p : testing::BoxInterior(2 * a, 2 * b, 2 * c, 600, rng))
    if (std::abs(p.x()) / a + std::abs(p.y()) / b + std::abs(p.z()) / c < 0.99) points.push_back(p);
  RockReport r;
  MakeRockFromPoints(Cloud(points), FileSpec(""), &r);
  const double V = 4 * a * b * c / 3, m = 1000 * V;
  EXPECT_NEAR(r.volume_m3, V, 1e-14);
  EXPECT_LT(
      MomentError(
          r, Eigen::Vector3d(m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)) / 10),
      1e-12);
  EXPECT_EQ(r.hull_vertices, 6);
}

TEST(MakeRock, CylinderFromRingScans) {
  // Solid cylinder R, H: V = pi R^2 H, I_axis = m R^2 / 2, I_perp = m (3 R^2 + H^2) / 12. The scan
  // has N points on each end circle: the inscribed N-gon prism's volume is short by
  // 1 - sin(2 pi/N) N / (2 pi) ~ (2 pi / N)^2 / 6 = 1.3e-5 for N = 720.
  const double R = 0.4, H = 0.3;
  const int N = 720;
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < N; ++k) {
    const double phi = 2 * kPi * (k + 0.25) / N;
    points.emplace_back(R * std::cos(phi), R * std::sin(phi), H / 2);
    points.emplace_back(R * std::cos(phi + 1e-3), R * std::sin(phi + 1e-3), -H / 2);
  }
  std::mt19937_64 rng(13);
  for (const auto& p : testing::BoxInterior(R, R, H, 500, rng)) points.push_back(p);
  RockReport r;
  MakeRockFromPoints(Cloud(points), FileSpec(""), &r);
  const double V = kPi * R * R * H, m = 1000 * V;
  EXPECT_LT(RelativeError(r.volume_m3, V), 2e-5);
  EXPECT_LT(MomentError(r, Eigen::Vector3d(m * (3 * R * R + H * H) / 12,
                                           m * (3 * R * R + H * H) / 12, m * R * R / 2)),
            5e-5);
  EXPECT_EQ(r.shape.shape_class, ShapeClass::kPlaty);  // 0.8 x 0.8 x 0.3: c/b = 0.375
}

TEST(MakeRock, DenselySampledEllipsoidConverges) {
  // Ellipsoid with semi-axes (p, q, r): V = 4 pi pqr / 3, I_x = m (q^2 + r^2) / 5. The hull of n
  // random surface points is an inner approximation; its relative volume error falls like 1/n
  // (measured with this seed: about 1e-2, 1e-3, 1e-4 for n = 1e3, 1e4, 1e5).
  const double p = 1.5, q = 1.0, s = 0.5;
  const double V = 4 * kPi * p * q * s / 3, m = 1000 * V;
  const Eigen::Vector3d exact =
      Eigen::Vector3d(q * q + s * s, p * p + s * s, p * p + q * q) * m / 5;
  std::mt19937_64 rng(14);
  const std::vector<std::pair<int, double>> bounds = {{1000, 3e-2}, {10000, 3e-3}, {100000, 3e-4}};
  for (const auto& [n, bound] : bounds) {
    RockReport r;
    MakeRockFromPoints(Cloud(testing::EllipsoidSurface(p, q, s, n, rng)), FileSpec(""), &r);
    const double volume_error = RelativeError(r.volume_m3, V), moment_error = MomentError(r, exact);
    std::printf("ellipsoid, %6d points: volume error %.2e, principal moment error %.2e\n", n,
                volume_error, moment_error);
    EXPECT_LT(volume_error, bound) << n;
    EXPECT_LT(moment_error, 2 * bound) << n;
    EXPECT_LT(r.centroid_m.norm(), 10 * bound) << n;
    EXPECT_LT(std::abs(r.principal_axes.col(0).x()), 1) << n;
    EXPECT_GT(std::abs(r.principal_axes.col(0).x()), 1 - bound)
        << n;  // smallest moment: along the long axis
  }
}

TEST(MakeRock, PrincipalFrameIsRightHandedAndHoldsTheVertices) {
  std::mt19937_64 rng(15);
  auto points = testing::EllipsoidSurface(1.2, 0.7, 0.4, 400, rng);
  const Eigen::Matrix3d turn = testing::RandomRotation(rng);
  for (auto& x : points) x = turn * x + Eigen::Vector3d(3, 4, 5);
  RockReport r;
  const RockShape rock = MakeRockFromPoints(Cloud(points), FileSpec("", 2700), &r);
  std::string why;
  EXPECT_TRUE(rock.IsValid(&why)) << why;
  EXPECT_LE(rock.inertia_kg_m2(0), rock.inertia_kg_m2(1));
  EXPECT_LE(rock.inertia_kg_m2(1), rock.inertia_kg_m2(2));
  EXPECT_NEAR(r.principal_axes.determinant(), 1, 1e-12);
  // The input inertia is diagonal in the principal frame, with the reported moments.
  const Eigen::Matrix3d diagonal =
      r.principal_axes.transpose() * r.inertia_kg_m2 * r.principal_axes;
  EXPECT_LT((diagonal - Eigen::Matrix3d(rock.inertia_kg_m2.asDiagonal())).norm(),
            1e-10 * diagonal.norm());
  // Every principal-frame vertex maps back onto an input point.
  for (const auto& v : rock.vertices_m) {
    const Eigen::Vector3d x = rock.centroid_input_m + rock.principal_to_input * v;
    double nearest = 1e9;
    for (const auto& y : points) nearest = std::min(nearest, (x - y).norm());
    EXPECT_LT(nearest, 1e-12);
  }
}

TEST(MakeRock, InvariantUnderRotationAndGeoreferencedTranslation) {
  // The same scan written twice: as measured, and rotated and moved to LV95-like coordinates.
  TempDir dir;
  std::mt19937_64 rng(16);
  auto points = testing::EllipsoidSurface(0.9, 0.6, 0.35, 1500, rng);
  talus::testing::Normal noise(0, 0.01);
  for (auto& x : points) x += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  const Eigen::Matrix3d turn = testing::RandomRotation(rng);
  const Eigen::Vector3d shift(2600123.4567, 1200456.789, 1543.21);
  std::vector<Eigen::Vector3d> moved;
  for (const auto& x : points) moved.push_back(turn * x + shift);

  RockReport a, b;
  MakeRock(FileSpec(dir.Write("scan.xyz", testing::XyzText(points)), 2650), &a);
  MakeRock(FileSpec(dir.Write("moved.xyz", testing::XyzText(moved)), 2650), &b);
  EXPECT_EQ(a.hull_vertices, b.hull_vertices);
  EXPECT_LT(RelativeError(b.volume_m3, a.volume_m3), 1e-9);
  EXPECT_LT(MomentError(b, a.principal_moments_kg_m2), 1e-9);
  EXPECT_LT((b.centroid_m - (turn * a.centroid_m + shift)).norm(), 1e-8);
  for (int k = 0; k < 3; ++k)
    EXPECT_GT(std::abs(b.principal_axes.col(k).dot(turn * a.principal_axes.col(k))), 1 - 1e-9);
  EXPECT_LT((b.shape.dimensions_m - a.shape.dimensions_m).norm(), 1e-8);
  EXPECT_NEAR(b.shape.sphericity, a.shape.sphericity, 1e-9);
  EXPECT_GT(b.recentred_by_m.norm(), 1e6);
}

// Built-ins without dimensions and point clouds scale to volume_m3 or mass_kg / density_kg_m3.
// (This test used a box of 1 x 2 x 3 m; dimensions now fix the size, see the next test.)
TEST(MakeRock, ScalesToVolumeOrMassAboutTheCentroid) {
  RockSpec spec;
  spec.builtin = "icosphere";  // no diameter: 1 m, scaled
  RockReport plain, scaled;
  const RockShape one = MakeRock(spec, &plain);
  spec.volume_m3 = 8 * one.volume_m3;  // linear factor 2, moments 2^5
  const RockShape big = MakeRock(spec, &scaled);
  EXPECT_NEAR(scaled.scale, 2, 1e-15);
  EXPECT_NEAR(big.volume_m3, 8 * one.volume_m3, 1e-14);
  EXPECT_LT(((big.inertia_kg_m2 - 32 * one.inertia_kg_m2).array() / big.inertia_kg_m2.array())
                .abs()
                .maxCoeff(),
            1e-14);
  EXPECT_NEAR(scaled.centroid_m.norm(), 0, 1e-15);
  spec.volume_m3.reset();
  spec.mass_kg = 1000;
  EXPECT_NEAR(MakeRock(spec).volume_m3, 1000 / 2700.0, 1e-14);
  EXPECT_FALSE(plain.density_from_mass);

  // A scan away from the origin: scaling about the origin instead would move the centroid.
  const Eigen::Vector3d at(5, -3, 2);
  std::vector<Eigen::Vector3d> corners;
  for (const auto& c : testing::BoxCorners(1, 2, 3)) corners.push_back(c + at);
  RockSpec file = FileSpec("", 2700);
  file.volume_m3 = 48.0;
  RockReport moved;
  const RockShape far = MakeRockFromPoints(Cloud(corners), file, &moved);
  EXPECT_NEAR(moved.scale, 2, 1e-14);
  EXPECT_NEAR(far.volume_m3, 48, 1e-12);
  EXPECT_LT((moved.centroid_m - at).norm(), 1e-12);
  // The same scan given a mass: scaled to mass_kg / density_kg_m3, the density kept.
  file.volume_m3.reset();
  file.mass_kg = 2700 * 48.0;
  const RockShape heavy = MakeRockFromPoints(Cloud(corners), file, &moved);
  EXPECT_NEAR(moved.scale, 2, 1e-14);
  EXPECT_NEAR(heavy.mass_kg, 2700 * 48.0, 1e-9);
  EXPECT_EQ(moved.density_kg_m3, 2700);
  EXPECT_FALSE(moved.density_from_mass);
}

// A block of given dimensions and mass keeps its dimensions; the density follows. Box: the
// volume is abc exactly up to rounding in the mass-property sums (1e-16), so density and mass
// hold to 1e-12 relative; the extents are untouched (no scaling at all: exact).
TEST(MakeRock, DimensionsAndMassSetTheDensity) {
  RockSpec spec;
  spec.builtin = "box";
  spec.dimensions_m = {0.46, 0.30, 0.20};
  spec.mass_kg = 40;
  ASSERT_TRUE(DimensionsFixSize(spec));
  RockReport r;
  const RockShape box = MakeRock(spec, &r);
  const double density = 40 / (0.46 * 0.30 * 0.20);
  EXPECT_LT(RelativeError(r.density_kg_m3, density), 1e-12);
  EXPECT_LT(RelativeError(box.mass_kg, 40), 1e-12);
  EXPECT_LT(RelativeError(r.mass_kg, 40), 1e-12);
  EXPECT_EQ(r.scale, 1);
  EXPECT_TRUE(r.density_from_mass);
  EXPECT_LT((r.shape.dimensions_m - Eigen::Vector3d(0.46, 0.30, 0.20)).norm(), 1e-12);
  EXPECT_NE(r.FullReport().find("(the mass over the volume of the given dimensions)"),
            std::string::npos)
      << r.FullReport();
  EXPECT_EQ(nlohmann::json::parse(r.ToJson())["density_from_mass"], true);

  // Every built-in whose dimensions fix its size: the extents stay, the mass is met.
  for (const auto& [name, dims] :
       std::vector<std::pair<std::string, std::vector<double>>>{{"ellipsoid", {0.46, 0.30, 0.20}},
                                                                {"rock", {0.46, 0.30, 0.20}},
                                                                {"icosphere", {0.4}},
                                                                {"cylinder", {0.4, 0.2}},
                                                                {"disk", {0.6, 0.1}}}) {
    RockSpec other = spec;
    other.builtin = name;
    other.dimensions_m = dims;
    RockSpec without_mass = other;
    without_mass.mass_kg.reset();
    RockReport a, b;
    MakeRock(without_mass, &a);
    const RockShape rock = MakeRock(other, &b);
    EXPECT_LT(RelativeError(rock.mass_kg, 40), 1e-12) << name;
    EXPECT_TRUE(b.shape.dimensions_m == a.shape.dimensions_m) << name;  // the same hull
    EXPECT_LT(RelativeError(b.density_kg_m3, 40 / a.volume_m3), 1e-12) << name;
  }

  // Dimensions and a volume contradict each other (unless the volume were exactly theirs).
  spec.mass_kg.reset();
  spec.volume_m3 = 0.1;
  EXPECT_FALSE(DimensionsFixSize(FileSpec("rock.ply")));
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("volume_m3 = 0.1 contradicts the dimensions of the box"), std::string::npos)
      << why;
  EXPECT_NE(RockError(spec).find("contradicts"), std::string::npos);
  // Built-ins without dimensions still scale; EOTA blocks of given size take the bevel instead.
  spec.dimensions_m.clear();
  spec.builtin = "icosphere";
  EXPECT_FALSE(DimensionsFixSize(spec));
  EXPECT_TRUE(spec.IsValid(&why)) << why;
  spec.builtin = "eota221";
  spec.dimensions_m = {0.93, 0.93, 0.47};
  EXPECT_FALSE(DimensionsFixSize(spec));
}

TEST(MakeRock, BuiltInRockTakesItsKnobs) {
  RockSpec spec;
  spec.builtin = "rock";
  spec.dimensions_m = {0.46, 0.30, 0.20};
  spec.shape_seed = 7;
  RockReport r;
  const RockShape seven = MakeRock(spec, &r);
  EXPECT_EQ(r.source, "rock 0.46 x 0.3 x 0.2 m, 32 points, roughness 0.15, seed 7");
  EXPECT_LE(r.hull_vertices, 32);
  // The bounding box in the input frame (not the principal-frame dimensions of the descriptors).
  Eigen::Vector3d lo = r.hull.vertices_m[0], hi = lo;
  for (const auto& v : r.hull.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  EXPECT_LT((hi - lo - Eigen::Vector3d(0.46, 0.30, 0.20)).norm(), 1e-12);
  spec.points = 12;
  spec.roughness = 0.4;
  MakeRock(spec, &r);
  EXPECT_EQ(r.source, "rock 0.46 x 0.3 x 0.2 m, 12 points, roughness 0.4, seed 7");
  EXPECT_LE(r.hull_vertices, 12);
  spec.points = 3;
  std::string why;
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("points = 3"), std::string::npos) << why;
  // Rocks k = 0, 1 of a run with base seed 7 get different shapes.
  spec.points = 32;
  spec.roughness = 0.15;
  spec.shape_seed = ShapeSeed(7, 0);
  const double v0 = MakeRock(spec).volume_m3;
  spec.shape_seed = ShapeSeed(7, 1);
  EXPECT_NE(MakeRock(spec).volume_m3, v0);
  EXPECT_NE(v0, seven.volume_m3);
}

// ShapeSeed is SplitMix64 (Steele, Lea & Flood 2014; Vigna's splitmix64.c): seeded with 0, its
// first outputs are e220a8397b1dcdaf, 6e789e6aa1b965f4, 06c45d188009454f (the published reference
// sequence). Exact integer arithmetic: compared exactly.
TEST(ShapeSeed, IsSplitMix64) {
  EXPECT_EQ(ShapeSeed(0, 0), 0xe220a8397b1dcdafULL);
  EXPECT_EQ(ShapeSeed(0, 1), 0x6e789e6aa1b965f4ULL);
  EXPECT_EQ(ShapeSeed(0, 2), 0x06c45d188009454fULL);
  // Distinct over many rocks and bases (a bijection of base + (index + 1) * gamma).
  std::vector<std::uint64_t> seeds;
  for (std::uint64_t base : {0ULL, 1ULL, 42ULL})
    for (std::uint64_t k = 0; k < 1000; ++k) seeds.push_back(ShapeSeed(base, k));
  std::sort(seeds.begin(), seeds.end());
  EXPECT_EQ(std::adjacent_find(seeds.begin(), seeds.end()), seeds.end());
}

TEST(MakeRock, BuiltInEota221MatchesTheChantSuraBlock) {
  RockSpec spec;
  spec.builtin = "eota221";
  spec.dimensions_m = {0.93, 0.93, 0.47};
  spec.density_kg_m3 = 2500;
  spec.mass_kg = 780;
  RockReport r;
  const RockShape rock = MakeRock(spec, &r);
  const RockShape reference = scenes::Eota221();
  EXPECT_NEAR(rock.mass_kg, 780, 1e-9);
  EXPECT_LT(
      ((rock.inertia_kg_m2 - reference.inertia_kg_m2).array() / reference.inertia_kg_m2.array())
          .abs()
          .maxCoeff(),
      1e-9);
  EXPECT_EQ(rock.vertices_m.size(), 24u);
  EXPECT_EQ(r.shape.shape_class, ShapeClass::kPlaty);
  EXPECT_NE(r.FullReport().find("platy (Zingg)"), std::string::npos) << r.FullReport();
}

TEST(MakeRock, SimplificationIsReported) {
  RockSpec spec;
  spec.builtin = "icosphere";
  spec.subdivisions = 3;
  spec.max_vertices = 40;
  RockReport r;
  const RockShape rock = MakeRock(spec, &r);
  ASSERT_TRUE(r.simplify.has_value());
  EXPECT_EQ(r.simplify->vertices_before, 642);
  EXPECT_LE(rock.vertices_m.size(), 40u);
  EXPECT_EQ(r.hull_vertices, static_cast<int>(rock.vertices_m.size()));
  EXPECT_GT(r.simplify->volume_error, 0);
  EXPECT_LT(r.simplify->volume_error, 0.2);
}

TEST(MakeRock, BadInputSaysWhatIsWrong) {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {dir.Write("three.xyz", "0 0 0\n1 0 0\n0 1 0\n"), "3 points; a rock needs at least 4"},
      {dir.Write("flat.xyz", "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0.5 0.5 0\n"), "coplanar"},
      {dir.Write("line.csv", "0,0,0\n1,1,1\n2,2,2\n3,3,3\n"), "collinear"},
      // Numbers whose squares overflow are out of range, not "collinear".
      {dir.Write("far.xyz", "0 0 0\n1e300 0 0\n0 1e300 0\n0 0 1e300\n"),
       "far.xyz:2: coordinates (1e+300"},
      {dir.Write("far.csv", "0,0,0\n1e10,0,0\n0,1,0\n0,0,1\n"), "out of range: beyond +-1e+09 m"},
      {dir.Write("nan.xyz", "nan 0 0\n0 nan 0\n0 0 nan\n1 2 3\n4 5 6\n"),
       "only 2 of 5 points are usable (3 non-finite"},
      // Fewer than 4 points in the file, some of them dropped: say so, not "1 point".
      {dir.Write("few.xyz", "nan 0 0\n1 2 3\n1 2 3\n"),
       "only 1 of 3 points are usable (1 non-finite, 1 duplicates"},
      {dir.Write("empty.ply", ""), "empty"},
      {dir.Write("junk.pcd", "not a point cloud\n"), "not a readable PCD file"},
      {dir.Write("rock.las", "LASF"), "unknown point cloud format '.las'"},
      {dir.File("missing.pts"), "no such file"},
  };
  for (const auto& [path, reason] : cases) {
    const std::string why = RockError(FileSpec(path));
    EXPECT_NE(why.find(path), std::string::npos) << why;
    EXPECT_NE(why.find(reason), std::string::npos) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
  }
  RockSpec bad = FileSpec(dir.File("missing.pts"));
  bad.density_kg_m3 = -1;
  EXPECT_NE(RockError(bad).find("density_kg_m3 = -1"), std::string::npos);
}

TEST(RockReport, JsonHasTheStableKeys) {
  RockSpec spec;
  spec.builtin = "box";
  spec.dimensions_m = {1, 2, 4};
  RockReport r;
  MakeRock(spec, &r);
  const nlohmann::json j = nlohmann::json::parse(r.ToJson());
  for (const char* key :
       {"volume_m3", "mass_kg", "density_kg_m3", "centroid_m", "principal_moments_kg_m2",
        "principal_axes", "dimensions_m", "shape_class", "sphericity", "hull_vertices",
        "hull_faces", "points_read", "points_used"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_DOUBLE_EQ(j["volume_m3"].get<double>(), 8);
  EXPECT_DOUBLE_EQ(j["mass_kg"].get<double>(), 8 * 2700);
  EXPECT_EQ(j["centroid_m"].size(), 3u);
  EXPECT_EQ(j["principal_axes"].size(), 3u);
  EXPECT_EQ(j["principal_axes"][0].size(), 3u);
  EXPECT_NEAR(std::abs(j["principal_axes"][0][2].get<double>()), 1,
              1e-12);  // smallest moment: along the 4 m side
  EXPECT_EQ(j["dimensions_m"], nlohmann::json({4.0, 2.0, 1.0}));
  EXPECT_EQ(j["shape_class"], "bladed");
  EXPECT_EQ(j["hull_vertices"], 8);
  EXPECT_EQ(j["hull_faces"], 12);
  EXPECT_EQ(j["points_read"], 0);
}

// The trial that made a wrong rock silently: a scan with stray returns. By default the rock is the
// clean scan's (the outliers removed, its hull exactly that of the clean points); with cleaning
// off the hull is many times larger and the report warns, in text and JSON.
TEST(MakeRock, StrayReturnsAreRemovedByDefaultAndWarnedAboutWhenKept) {
  std::mt19937_64 rng(41);
  // Semi-axes 1.4 x 1.0 x 0.8 m: 4/3 pi abc = 4.69 m^3 (the trial's rock was 4.6 m^3).
  const auto clean = testing::EllipsoidSurface(1.4, 1.0, 0.8, 6000, rng);
  auto dirty = clean;
  for (const auto& p : testing::FarOutliers(60, 3, 10, rng)) dirty.push_back(p);
  RockReport reference;
  MakeRockFromPoints(Cloud(clean), FileSpec(""), &reference);
  EXPECT_NEAR(reference.volume_m3, 4.0 / 3.0 * kPi * 1.4 * 1.0 * 0.8, 0.01 * 4.69);  // sampled
  EXPECT_TRUE(reference.warnings.empty());

  RockReport cleaned;
  MakeRockFromPoints(Cloud(dirty), FileSpec(""), &cleaned);
  EXPECT_EQ(cleaned.clean.outliers, 60u);
  // Exactly the clean points are left, so the hull is theirs up to round-off.
  EXPECT_NEAR(cleaned.volume_m3, reference.volume_m3, 1e-12 * reference.volume_m3);
  EXPECT_TRUE(cleaned.warnings.empty());
  ASSERT_TRUE(cleaned.hull_check.has_value());
  EXPECT_FALSE(cleaned.hull_check->Dominated());

  RockSpec off = FileSpec("");
  off.clean = CleanOptions::Off();
  RockReport kept;
  MakeRockFromPoints(Cloud(dirty, "scan.xyz"), off, &kept);
  EXPECT_GT(kept.volume_m3, 10 * reference.volume_m3);
  ASSERT_EQ(kept.warnings.size(), 1u);
  EXPECT_NE(kept.warnings[0].find("scan.xyz: a few points dominate the rock's hull"),
            std::string::npos)
      << kept.warnings[0];
  EXPECT_NE(kept.FullReport().find("WARNING: scan.xyz: a few points dominate"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(kept.ToJson());
  EXPECT_EQ(j["warnings"].size(), 1u);
  EXPECT_GT(j["hull_check"]["far_points"].get<int>(), 30);  // those beyond 3 core radii (~4 m)
  EXPECT_TRUE(j["hull_check"]["dominated"].get<bool>());
}

}  // namespace
}  // namespace talus::pointclouds
