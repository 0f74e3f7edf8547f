#include "ensemble/release.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "ensemble/runner.hpp"
#include "fixtures.hpp"

namespace talus::ensemble {
namespace {

TEST(Release, StartDependsOnSeedAndRockOnly) {
  const Scene scene = testing::SmallPlane(30, 20, 10);
  ReleaseSpec spec = testing::PointRelease({{5, 0}, {6, 1}}, 4);
  std::string why;
  ASSERT_TRUE(spec.IsValid(&why)) << why;
  const RockState a = Release(scene, spec, 5).start;
  const RockState b = Release(scene, spec, 5).start;
  EXPECT_EQ(a.orientation.coeffs(), b.orientation.coeffs());
  EXPECT_NE(Release(scene, spec, 6).start.orientation.coeffs(), a.orientation.coeffs());
  EXPECT_EQ(spec.ReleaseOf(5), 1);
  EXPECT_DOUBLE_EQ(a.position_m.x(), 6);
  TerrainSample ground;
  ASSERT_TRUE(scene.terrain.Sample(6, 1, &ground));
  EXPECT_NEAR(a.position_m.z(), ground.height_m + spec.height_m, 1e-12);
  spec.seed = 2;
  EXPECT_NE(Release(scene, spec, 5).start.orientation.coeffs(), a.orientation.coeffs());
}

TEST(Release, FixedOrientationRotatesTheShapeAsGiven) {
  Scene scene = testing::SmallPlane(30, 20, 10);
  scene.rock =
      MakeRockShape(MakeBox(0.2, 0.5, 1.0), 2700);  // principal frame differs from the input axes
  ReleaseSpec spec = testing::PointRelease({{5, 0}}, 1);
  const Eigen::Quaterniond user(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  spec.orientation = user;
  spec.angular_velocity_rad_s = Eigen::Vector3d(0, 0, 2);
  const RockState s = Release(scene, spec, 0).start;
  const Eigen::Quaterniond shape = s.orientation * scene.rock.principal_to_input.conjugate();
  EXPECT_NEAR(std::abs(shape.dot(user)), 1.0, 1e-12);
  EXPECT_TRUE((s.orientation * s.angular_velocity_rad_s).isApprox(Eigen::Vector3d(0, 0, 2), 1e-12));
}

// A run without an orientation of its own takes the spec's: a fixed one for every rock when given
// (a measured orientation of a campaign), random per rock otherwise.
TEST(Release, RunsWithoutOrientationTakeTheSpecs) {
  const Scene scene = testing::SmallPlane(30, 20, 10);
  ReleaseSpec spec;
  spec.runs.resize(2);
  spec.runs[0].id = "own";
  spec.runs[0].xy_m = {5, 0};
  spec.runs[0].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitX()));
  spec.runs[1].id = "spec's";
  spec.runs[1].xy_m = {6, 0};
  spec.rocks_per_release = 2;
  std::string why;
  ASSERT_TRUE(spec.IsValid(&why)) << why;
  const auto shape_of = [&](long rock) {
    return Release(scene, spec, rock).start.orientation * scene.rock.principal_to_input.conjugate();
  };
  EXPECT_NE(shape_of(2).coeffs(), shape_of(3).coeffs());  // random: the spec fixes none
  const Eigen::Quaterniond fixed(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()));
  spec.orientation = fixed;
  for (long rock : {2, 3}) EXPECT_NEAR(std::abs(shape_of(rock).dot(fixed)), 1.0, 1e-12);
  for (long rock : {0, 1})
    EXPECT_NEAR(std::abs(shape_of(rock).dot(*spec.runs[0].orientation)), 1.0, 1e-12);
}

TEST(Release, LinesAndPolygonsSampleOnThem) {
  const Scene scene = testing::SmallPlane(30, 20, 10);
  ReleaseSpec spec;
  spec.releases.push_back({ReleaseGeometry::Kind::kLine, {{{2, -3}, {2, 3}, {8, 3}}}});
  spec.releases.push_back(
      {ReleaseGeometry::Kind::kPolygon,
       {{{10, -2}, {14, -2}, {14, 2}, {10, 2}}, {{11, -1}, {13, -1}, {13, 1}, {11, 1}}}});
  spec.rocks_per_release = 200;
  std::string why;
  ASSERT_TRUE(spec.IsValid(&why)) << why;
  for (long rock = 0; rock < 200; ++rock) {
    const Eigen::Vector3d p = Release(scene, spec, rock).start.position_m;
    const bool on_first = std::abs(p.x() - 2) < 1e-12 && std::abs(p.y()) <= 3;
    const bool on_second = std::abs(p.y() - 3) < 1e-12 && p.x() >= 2 && p.x() <= 8;
    EXPECT_TRUE(on_first || on_second) << p.transpose();
  }
  for (long rock = 200; rock < 400; ++rock) {
    const Eigen::Vector3d p = Release(scene, spec, rock).start.position_m;
    EXPECT_TRUE(p.x() >= 10 && p.x() <= 14 && std::abs(p.y()) <= 2) << p.transpose();
    EXPECT_FALSE(std::abs(p.x() - 12) < 1 && std::abs(p.y()) < 1)
        << "in the hole: " << p.transpose();
  }
}

TEST(Release, InvalidSpecsNameTheField) {
  std::string why;
  EXPECT_FALSE(ReleaseSpec{}.IsValid(&why));
  ReleaseSpec spec = testing::PointRelease({{1, 1}}, 0);
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("rocks"), std::string::npos) << why;
  spec.rocks_per_release = 1;
  spec.releases.push_back({ReleaseGeometry::Kind::kPolygon, {{{0, 0}, {1, 1}, {2, 2}}}});
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_NE(why.find("sliver"), std::string::npos) << why;
}

// Run ids must be unique; the check was quadratic in the runs (a 10^5-row run table took a minute
// to load). 300 000 runs now take well under a second; the quadratic check would take minutes.
TEST(Release, RunIdsAreUniqueAndCheckedInTimeInProportion) {
  ReleaseSpec spec;
  spec.rocks_per_release = 1;
  spec.runs.resize(300000);
  for (std::size_t r = 0; r < spec.runs.size(); ++r) {
    spec.runs[r].id = std::to_string(r);
    spec.runs[r].xy_m = {5, 0};
  }
  std::string why;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(spec.IsValid(&why)) << why;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 30.0);  // a wide margin for sanitizer builds and loaded machines
  spec.runs.back().id = "17";
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_EQ(why, "run 17: the id appears twice");
}

// A polygon of (nearly) no area would start every rock at its first vertex (the sampler finds no
// inside point): it is invalid, with its area and bounding box. A thin strip across its box that
// covers more than kMinPolygonFill of it is fine, and rocks start inside it.
TEST(Release, SliverPolygonsAreInvalidThinStripsAreNot) {
  const ReleaseGeometry sliver{ReleaseGeometry::Kind::kPolygon,
                               {{{0, 0}, {100, 100}, {99.9999, 100.0001}}}};
  const std::string why = ReleaseGeometryProblem(sliver);
  EXPECT_NE(why.find("a sliver: its area (0.01 m2)"), std::string::npos) << why;
  EXPECT_NE(why.find("bounding box (100 x 100 m)"), std::string::npos) << why;
  ReleaseSpec spec = testing::PointRelease({{1, 1}}, 1);
  spec.releases = {sliver};
  std::string spec_why;
  EXPECT_FALSE(spec.IsValid(&spec_why));
  EXPECT_NE(spec_why.find("release 0: a sliver"), std::string::npos) << spec_why;

  // 1.4 m wide along the diagonal of a 20 x 20 m box: 38 m2 of 400, 9.5 %.
  const ReleaseGeometry strip{ReleaseGeometry::Kind::kPolygon,
                              {{{0, -9}, {1, -10}, {20, 9}, {19, 10}}}};
  EXPECT_EQ(ReleaseGeometryProblem(strip), "");
  const Scene scene = testing::SmallPlane(30, 20, 10);
  spec.releases = {strip};
  spec.rocks_per_release = 200;
  for (long rock = 0; rock < 200; ++rock) {
    const Eigen::Vector3d p = Release(scene, spec, rock).start.position_m;
    EXPECT_TRUE(InsidePolygon(strip.rings, p.head<2>())) << p.transpose();
  }

  const ReleaseGeometry far{ReleaseGeometry::Kind::kPolygon, {{{0, 0}, {1e300, 0}, {0, 1e300}}}};
  EXPECT_NE(ReleaseGeometryProblem(far).find("coordinates out of range"), std::string::npos)
      << ReleaseGeometryProblem(far);
}

// Specs that would silently misplace rocks are invalid: a line of zero length (every rock at one
// point), holes that cover the whole polygon (the sampler finds no inside point), and more rocks
// than a run can hold (rocks x releases overflowed to a run of no rock at all).
TEST(Release, DegenerateGeometriesAndTooManyRocksAreInvalid) {
  std::string why;
  ReleaseSpec line;
  line.releases.push_back({ReleaseGeometry::Kind::kLine, {{{3, 0}, {3, 0}}}});
  EXPECT_FALSE(line.IsValid(&why));
  EXPECT_NE(why.find("positive length"), std::string::npos) << why;

  ReleaseSpec holed;
  const std::vector<Eigen::Vector2d> square = {{3, -1}, {5, -1}, {5, 1}, {3, 1}};
  holed.releases.push_back({ReleaseGeometry::Kind::kPolygon, {square, square}});
  EXPECT_FALSE(holed.IsValid(&why));
  EXPECT_NE(why.find("holes cover"), std::string::npos) << why;

  ReleaseSpec many = testing::PointRelease({{1, 1}, {2, 2}}, std::numeric_limits<long>::max());
  EXPECT_FALSE(many.IsValid(&why));
  EXPECT_NE(why.find("more than"), std::string::npos) << why;
  many.rocks_per_release = ReleaseSpec::kMaxTotalRocks / 2;
  EXPECT_TRUE(many.IsValid(&why)) << why;
}

// Rocks start anywhere on a line or inside a polygon, so a nodata cell there is found even when
// every vertex is on valid terrain.
TEST(Release, PointOffTerrainFindsNodataAlongLinesAndInsidePolygons) {
  Scene scene = testing::SmallPlane(30, 20, 10);  // x 0 .. 30, y -10 .. 10, 1 m cells
  Heightfield heights = scene.terrain.heights();
  const GridGeometry& g = heights.grid;
  const int i = 10, j = 5;  // the node at (10, -5)
  heights.z_m[static_cast<std::size_t>(j) * g.nx + i] = std::nan("");
  const Terrain terrain(heights, 0);
  // Cells touching the nodata node: x in [9, 11], y in [-6, -4].
  const ReleaseGeometry point{ReleaseGeometry::Kind::kPoint, {{{5, 0}}}};
  EXPECT_FALSE(PointOffTerrain(terrain, point));
  const ReleaseGeometry crossing{ReleaseGeometry::Kind::kLine, {{{5, -5}, {15, -5}}}};
  const auto on_line = PointOffTerrain(terrain, crossing);
  ASSERT_TRUE(on_line);
  EXPECT_TRUE(on_line->x() >= 9 && on_line->x() <= 11) << on_line->transpose();
  const ReleaseGeometry beside{ReleaseGeometry::Kind::kLine, {{{5, -2}, {15, -2}}}};
  EXPECT_FALSE(PointOffTerrain(terrain, beside));
  const ReleaseGeometry around{ReleaseGeometry::Kind::kPolygon,
                               {{{7, -8}, {13, -8}, {13, -2}, {7, -2}}}};
  const auto inside = PointOffTerrain(terrain, around);
  ASSERT_TRUE(inside);
  EXPECT_TRUE(std::abs(inside->x() - 10) < 1 && std::abs(inside->y() + 5) < 1)
      << inside->transpose();  // a cell centre
  // A hole around the nodata cells makes the polygon fine again.
  const ReleaseGeometry holed{
      ReleaseGeometry::Kind::kPolygon,
      {{{7, -8}, {13, -8}, {13, -2}, {7, -2}}, {{8, -7}, {12, -7}, {12, -3}, {8, -3}}}};
  EXPECT_FALSE(PointOffTerrain(terrain, holed));
  const ReleaseGeometry elsewhere{ReleaseGeometry::Kind::kPolygon,
                                  {{{15, -8}, {20, -8}, {20, -2}, {15, -2}}}};
  EXPECT_FALSE(PointOffTerrain(terrain, elsewhere));
}

// Block sizes. ScaleRockShape against the shape built at the scaled size: a box of 1 x 2 x 3 m
// scaled by 1.7 is the box of 1.7 x 3.4 x 5.1 m at the same density (mass x 1.7^3, moments x 1.7^5),
// to rounding (1e-12 relative).
TEST(BlockSizes, AScaledShapeIsTheShapeOfTheScaledSize) {
  const RockShape rock = MakeRockShape(MakeBox(1, 2, 3), 2700);
  const RockShape scaled = ScaleRockShape(rock, 1.7);
  const RockShape built = MakeRockShape(MakeBox(1.7, 3.4, 5.1), 2700);
  EXPECT_NEAR(scaled.mass_kg, built.mass_kg, 1e-12 * built.mass_kg);
  EXPECT_NEAR(scaled.volume_m3, built.volume_m3, 1e-12 * built.volume_m3);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(scaled.inertia_kg_m2[k], built.inertia_kg_m2[k], 1e-12 * built.inertia_kg_m2[k]);
  EXPECT_NEAR(scaled.length_m, built.length_m, 1e-12);
  EXPECT_NEAR(scaled.bounding_radius_m, built.bounding_radius_m, 1e-12);
  std::string why;
  EXPECT_TRUE(scaled.IsValid(&why)) << why;
}

// The quantiles in closed form: uniform at u = 1/2 is the midpoint; the power law's exceedance
// P(V >= Q(u)) = (Q^-b - max^-b) / (min^-b - max^-b) is 1 - u; the untruncated log-normal's median
// is median_m3 and Q(Phi(1)) = median e^sigma (Phi(1) = 0.841344746068543); every truncated one
// maps 0 and 1 to its bounds.
TEST(BlockSizes, QuantilesAreTheDistributionsClosedForms) {
  VolumeDistribution uniform{VolumeDistribution::Kind::kUniform, 0.5, 2.5};
  EXPECT_DOUBLE_EQ(uniform.Quantile(0.5), 1.5);
  VolumeDistribution power{VolumeDistribution::Kind::kPowerLaw, 0.1, 10};
  power.exponent = 0.6;
  const double a = std::pow(0.1, -0.6), b = std::pow(10.0, -0.6);
  for (double u : {0.0, 0.1, 0.5, 0.9, 0.999}) {
    const double v = power.Quantile(u);
    EXPECT_NEAR((std::pow(v, -0.6) - b) / (a - b), 1 - u, 1e-12) << u;
  }
  EXPECT_DOUBLE_EQ(power.Quantile(0), 0.1);
  EXPECT_NEAR(power.Quantile(1), 10, 1e-12);
  VolumeDistribution log_normal{VolumeDistribution::Kind::kLogNormal};
  log_normal.median_m3 = 2;
  log_normal.sigma = 0.8;
  EXPECT_NEAR(log_normal.Quantile(0.5), 2, 1e-12);
  EXPECT_NEAR(log_normal.Quantile(0.841344746068543), 2 * std::exp(0.8), 1e-9);
  log_normal.min_m3 = 0.5;
  log_normal.max_m3 = 4;
  EXPECT_NEAR(log_normal.Quantile(0), 0.5, 1e-12);
  EXPECT_NEAR(log_normal.Quantile(1), 4, 1e-12);
  std::string why;
  for (const VolumeDistribution& d : {uniform, power, log_normal})
    EXPECT_TRUE(d.IsValid(&why)) << why;
}

// The drawn volumes of 4000 rocks follow the distribution: the Kolmogorov-Smirnov distance of
// their empirical CDF to the stated one stays below 1.95 / sqrt(n), the asymptotic critical value
// at the 0.001 level (Massey 1951, JASA 46); and each rock's mass is its volume at the density.
TEST(BlockSizes, RocksDrawTheirVolumesFromTheDistribution) {
  Scene scene = testing::SmallPlane(30, 20, 10);
  scene.rock = MakeRockShape(MakeBox(1, 1, 1), 2700);
  const long n = 4000;
  ReleaseSpec spec = testing::PointRelease({{5, 0}}, n);
  spec.volume.kind = VolumeDistribution::Kind::kPowerLaw;
  spec.volume.min_m3 = 0.05;
  spec.volume.max_m3 = 5;
  spec.volume.exponent = 0.5;
  std::string why;
  ASSERT_TRUE(spec.IsValid(&why)) << why;
  std::vector<double> volumes;
  for (long rock = 0; rock < n; ++rock) {
    const ReleasedRock r = Release(scene, spec, rock);
    const double v = RockVolume(spec, rock);
    ASSERT_NEAR(r.shape->volume_m3, v, 1e-12 * v) << rock;
    ASSERT_NEAR(r.shape->mass_kg, 2700 * v, 1e-9 * 2700 * v) << rock;
    volumes.push_back(v);
  }
  std::sort(volumes.begin(), volumes.end());
  const double a = std::pow(0.05, -0.5), b = std::pow(5.0, -0.5);
  double distance = 0;
  for (long k = 0; k < n; ++k) {
    const double cdf = (a - std::pow(volumes[k], -0.5)) / (a - b);
    distance = std::max({distance, std::abs(cdf - double(k) / n), std::abs(cdf - double(k + 1) / n)});
  }
  EXPECT_LT(distance, 1.95 / std::sqrt(double(n)));
  // The rock's own stream: another seed, another volume.
  ReleaseSpec other = spec;
  other.seed = 2;
  EXPECT_NE(RockVolume(other, 17), RockVolume(spec, 17));
  // Orientations do not change with sizes: the volume has its own stream.
  ReleaseSpec fixed = spec;
  fixed.volume = {};
  EXPECT_EQ(Release(scene, fixed, 17).start.orientation.coeffs(),
            Release(scene, spec, 17).start.orientation.coeffs());
}

TEST(BlockSizes, BadDistributionsNameTheKey) {
  std::string why;
  VolumeDistribution d{VolumeDistribution::Kind::kUniform, 2, 1};
  EXPECT_FALSE(d.IsValid(&why));
  EXPECT_NE(why.find("max_m3"), std::string::npos) << why;
  d = {VolumeDistribution::Kind::kPowerLaw, 0.1, 1};
  d.exponent = 0;
  EXPECT_FALSE(d.IsValid(&why));
  EXPECT_NE(why.find("exponent"), std::string::npos) << why;
  d = {VolumeDistribution::Kind::kLogNormal};
  d.median_m3 = 1;
  d.sigma = -1;
  EXPECT_FALSE(d.IsValid(&why));
  EXPECT_NE(why.find("sigma"), std::string::npos) << why;
  d.sigma = 0.5;
  d.min_m3 = 100;
  d.max_m3 = 200;
  EXPECT_FALSE(d.IsValid(&why));  // beyond 8 sigma of the median
  ReleaseSpec spec = testing::PointRelease({{5, 0}}, 1);
  spec.volume = {VolumeDistribution::Kind::kUniform, -1, 1};
  EXPECT_FALSE(spec.IsValid(&why));
  EXPECT_EQ(why.rfind("volume.min_m3", 0), 0u) << why;
}

// A population of sizes runs to the same bits on any number of threads, and the mixed masses are
// what each rock ran with.
TEST(BlockSizes, EnsemblesOfMixedSizesAreTheSameForAnyThreadCount) {
  Scene scene = testing::SmallPlane(35, 15, 10);
  ReleaseSpec spec = testing::PointRelease({{3, 0}}, 24);
  spec.volume = {VolumeDistribution::Kind::kLogNormal};
  spec.volume.median_m3 = 0.064;
  spec.volume.sigma = 0.6;
  struct Masses : RockSink {
    std::vector<double> mass, runout;
    void OnRock(const RockOutcome& o) override {
      mass.push_back(o.shape->mass_kg);
      runout.push_back(o.result.runout_m);
    }
  };
  std::vector<Masses> runs(2);
  for (int threads : {1, 2}) {
    EnsembleOptions options;
    options.threads = threads;
    RunEnsemble(scene, spec, options, &runs[static_cast<std::size_t>(threads - 1)]);
  }
  EXPECT_EQ(runs[0].mass, runs[1].mass);
  EXPECT_EQ(runs[0].runout, runs[1].runout);
  for (long rock = 0; rock < 24; ++rock)
    EXPECT_NEAR(runs[0].mass[static_cast<std::size_t>(rock)], 2700 * RockVolume(spec, rock),
                1e-9 * runs[0].mass[static_cast<std::size_t>(rock)]);
}

}  // namespace
}  // namespace talus::ensemble
