#include "solver/terrain.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

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
  // A nodata node anywhere in the box, also before finite nodes in the scan and away from the
  // centre's cell: 5 x 5 flat nodes 2 m apart, the box of (5, 5) +- 2.9 m spans nodes 1 .. 4, and
  // node (2, 1) is nodata.
  Heightfield flat;
  flat.grid = {5, 5, 0.0, 0.0, 2.0, 2.0};
  flat.z_m.assign(25, 0.0);
  ASSERT_TRUE(Terrain(flat, 0).PlaneAround(5, 5, 2.9, &plane));
  flat.z_m[1 * 5 + 2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(Terrain(flat, 0).PlaneAround(5, 5, 2.9, &plane));
}

TEST(Terrain, LocalPlaneBoundsTheTerrainInTheBox) {
  // z = x y / 100 departs from its tangent plane at (x0, y0) by (x - x0)(y - y0)/100 everywhere
  // (the grid reproduces it exactly), which over the box of half-width r is largest, r^2 / 100, at
  // the box's corners: 0.0025 m for r = 0.5 m inside one cell, 0.0225 m for r = 1.5 m across four.
  // The bound adds 1e-6 m for rounding; exact arithmetic up to round-off: tolerance 1e-14 m.
  const Terrain t = Saddle();
  Terrain::LocalPlane plane;
  ASSERT_TRUE(t.PlaneAround(11, 21, 0.5, &plane));
  EXPECT_NEAR(plane.at.height_m, 2.31, 1e-14);
  EXPECT_NEAR(plane.slope_x, 0.21, 1e-14);
  EXPECT_NEAR(plane.slope_y, 0.11, 1e-14);
  EXPECT_NEAR(plane.deviation_m, 0.0025 + 1e-6, 1e-14);
  ASSERT_TRUE(t.PlaneAround(12.3, 21.8, 1.5, &plane));
  EXPECT_NEAR(plane.deviation_m, 0.0225 + 1e-6, 1e-14);
  EXPECT_FALSE(t.PlaneAround(10.2, 21, 0.5, &plane));  // the box reaches beyond x0
}

// A rough grid of 41 x 31 nodes at 1.5 m spacing (slopes of h below 10).
Heightfield RoughHeights() {
  Heightfield hf;
  hf.grid = {41, 31, 100.0, -20.0, 1.5, 1.5};
  for (int j = 0; j < 31; ++j)
    for (int i = 0; i < 41; ++i)
      hf.z_m.push_back(0.7 * i + 3 * std::sin(1.3 * i) * std::cos(0.7 * j) +
                       0.2 * ((i * 7 + j * 13) % 5));
  return hf;
}

// The largest |h - plane| on a lattice of (points + 1)^2 points over the box (x0, y0) +- r.
double LatticeDeparture(const Terrain& t, const Terrain::LocalPlane& plane, double x0, double y0,
                        double r, int points) {
  double sampled = 0;
  for (int a = 0; a <= points; ++a)
    for (int b = 0; b <= points; ++b) {
      const double x = x0 - r + 2 * r * a / points, y = y0 - r + 2 * r * b / points;
      double h = 0;
      EXPECT_TRUE(t.Height(x, y, &h));
      const double on_plane =
          plane.at.height_m + plane.slope_x * (x - x0) + plane.slope_y * (y - y0);
      sampled = std::max(sampled, std::abs(h - on_plane));
    }
  return sampled;
}

TEST(Terrain, LocalPlaneBoundIsTheLargestDepartureOverTheBox) {
  // A rough grid (41 x 31 nodes, 1.5 m spacing) and boxes inside a cell, across cell edges and
  // over many cells: the bound is at least |h - plane| at every point of a fine lattice over the
  // box (edges included), and it is tight: at most that lattice's largest value plus the 1e-6 m
  // rounding allowance and what a lattice of 200 x 200 can miss between its points (the slope of
  // h - plane, below 10 here, times the lattice's spacing).
  const Heightfield hf = RoughHeights();
  const Terrain t(hf, 0);
  // Boxes of at most Terrain::kExactCells cells a side (1.5 m cells: r <= 3 m).
  const double boxes[][3] = {{120.4, -5.3, 0.3}, {121.4, -4.6, 0.8}, {130.0, 0.0, 0.7},
                             {140.2, 10.9, 2.9}, {103.0, -17.0, 2.9}};
  for (const auto& [x0, y0, r] : boxes) {
    Terrain::LocalPlane plane;
    ASSERT_TRUE(t.PlaneAround(x0, y0, r, &plane));
    constexpr int kPoints = 200;
    const double sampled = LatticeDeparture(t, plane, x0, y0, r, kPoints);
    EXPECT_GE(plane.deviation_m, sampled) << "box at " << x0 << ", " << y0 << " +- " << r;
    EXPECT_LE(plane.deviation_m, sampled + 1e-6 + 10 * 2 * r / kPoints)
        << "box at " << x0 << ", " << y0 << " +- " << r;
  }
}

TEST(Terrain, LocalPlaneBoundOfALargeBoxHoldsFromThePyramidsBlocks) {
  // Boxes wider than Terrain::kExactCells cells are bounded by the plane pyramid's blocks: the bound
  // must still hold at every point of a fine lattice over the box. It is looser than the
  // cell-by-cell bound (a block reaches beyond the box, and its plane is not the tangent plane):
  // against the largest departure of the nodes of the cells the box touches, measured at most
  // 2.70 times; asserted within 4 times, so that a pyramid that bounds by far too much (and makes
  // detection test every vertex) fails. On the rough grid (1.5 m cells) and a fine one (0.05 m)
  // with boxes of 5 to 60 cells.
  double worst_ratio = 0;
  for (const double cell : {1.5, 0.05}) {
    Heightfield hf = RoughHeights();
    hf.grid.dx_m = hf.grid.dy_m = cell;
    hf.grid.x0_m = 100.0;
    hf.grid.y0_m = -20.0;
    if (cell < 1) {  // a larger, finer grid: 401 x 301 nodes of 0.05 m
      hf.grid.nx = 401;
      hf.grid.ny = 301;
      hf.z_m.clear();
      for (int j = 0; j < 301; ++j)
        for (int i = 0; i < 401; ++i)
          hf.z_m.push_back(0.02 * i + 0.3 * std::sin(0.13 * i) * std::cos(0.07 * j) +
                           0.01 * ((i * 7 + j * 13) % 5));
    }
    const Terrain t(hf, 0);
    for (const double span_cells : {5.0, 9.0, 20.0, 60.0}) {
      const double r = 0.5 * span_cells * cell;
      if (span_cells >= hf.grid.ny - 1) continue;  // wider than the rough grid
      for (const double fx : {0.21, 0.5, 0.77}) {
        const double x0 = hf.grid.x0_m + r + fx * (hf.grid.x_max_m() - hf.grid.x0_m - 2 * r);
        const double y0 = hf.grid.y0_m + r + (1 - fx) * (hf.grid.y_max_m() - hf.grid.y0_m - 2 * r);
        Terrain::LocalPlane plane;
        ASSERT_TRUE(t.PlaneAround(x0, y0, r, &plane));
        const double sampled = LatticeDeparture(t, plane, x0, y0, r, 120);
        EXPECT_GE(plane.deviation_m, sampled)
            << "cell " << cell << ", box at " << x0 << ", " << y0 << " +- " << r;
        // The exact bound over the nodes of the cells the box touches, and the residuals.
        double nodes = 0;
        for (int j = 0; j < hf.grid.ny; ++j)
          for (int i = 0; i < hf.grid.nx; ++i) {
            const double x = hf.grid.x0_m + i * cell, y = hf.grid.y0_m + j * cell;
            if (std::abs(x - x0) > r + cell || std::abs(y - y0) > r + cell) continue;
            const double on_plane =
                plane.at.height_m + plane.slope_x * (x - x0) + plane.slope_y * (y - y0);
            nodes = std::max(nodes, std::abs(hf.z_m[j * hf.grid.nx + i] - on_plane));
          }
        EXPECT_LE(plane.deviation_m, 4 * nodes + 1e-6)
            << "cell " << cell << ", box at " << x0 << ", " << y0 << " +- " << r;
        worst_ratio = std::max(worst_ratio, plane.deviation_m / nodes);
      }
    }
  }
  std::printf("largest pyramid bound / departure at the box's nodes: %.2f\n", worst_ratio);
}

TEST(Terrain, MaxAbovePlaneBoundsTheTerrainOverTheBox) {
  // A rough 41 x 31 node grid (1.5 m spacing): the bound must be at least the terrain's height
  // above the plane at every point of the box (sampled on a fine lattice, edges included), and at
  // most the largest node value of the cells around the box (its definition). Exact arithmetic
  // up to round-off: tolerance 1e-12 m.
  const Heightfield hf = RoughHeights();
  const Terrain t(hf, 0);
  const Terrain::Plane plane{120.0, -5.0, 12.0, 0.4, -0.1};
  auto plane_at = [&](double x, double y) {
    return plane.z_m + plane.slope_x * (x - plane.x_m) + plane.slope_y * (y - plane.y_m);
  };
  const Terrain::Box boxes[] = {{103.0, 111.5, -14.0, -8.0},
                                {130.0, 130.0, 0.0, 0.0},
                                {101.5, 160.0, -20.0, 25.0},
                                {150.7, 151.2, 10.1, 10.2}};
  for (const Terrain::Box& box : boxes) {
    double above = 0;
    ASSERT_TRUE(t.MaxAbovePlane(box, plane, &above));
    double sampled = -1e9;
    for (int a = 0; a <= 40; ++a)
      for (int b = 0; b <= 40; ++b) {
        const double x = box.x_lo_m + a * (box.x_hi_m - box.x_lo_m) / 40;
        const double y = box.y_lo_m + b * (box.y_hi_m - box.y_lo_m) / 40;
        double h = 0;
        ASSERT_TRUE(t.Height(x, y, &h));
        sampled = std::max(sampled, h - plane_at(x, y));
      }
    EXPECT_GE(above, sampled - 1e-12);
    double nodes = -1e9;
    for (int j = 0; j < 31; ++j)
      for (int i = 0; i < 41; ++i) {
        const double x = 100.0 + 1.5 * i, y = -20.0 + 1.5 * j;
        if (x >= box.x_lo_m - 1.5 && x <= box.x_hi_m + 1.5 && y >= box.y_lo_m - 1.5 &&
            y <= box.y_hi_m + 1.5)
          nodes = std::max(nodes, hf.z_m[j * 41 + i] - plane_at(x, y));
      }
    EXPECT_LE(above, nodes + 1e-12);
  }
  double above = 0;
  EXPECT_FALSE(t.MaxAbovePlane({99.9, 105, 0, 1}, plane, &above));   // beyond x0
  EXPECT_FALSE(t.MaxAbovePlane({150, 160.1, 0, 1}, plane, &above));  // beyond the last node
  Heightfield holed = hf;
  holed.z_m[10 * 41 + 20] = std::numeric_limits<double>::quiet_NaN();  // node (20, 10): (130, -5)
  const Terrain h(holed, 0);
  EXPECT_FALSE(h.MaxAbovePlane({128.6, 129.0, -6.0, -5.5}, plane, &above));  // a cell with it
  EXPECT_TRUE(h.MaxAbovePlane({125.0, 128.4, -6.0, -5.5}, plane, &above));   // none
}

// SampleBelow answers as Sample where the point lies below the terrain, the same bits, and false
// where it lies at or above it, outside the grid or over a nodata corner (contact detection takes
// a normal only where a vertex is below the terrain).
TEST(Terrain, SampleBelowIsSampleUnderTheTerrainOnly) {
  Heightfield hf;
  hf.grid = {6, 5, 100.0, 200.0, 2.0, 2.5};
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> height(-3.0, 3.0);
  for (int k = 0; k < 30; ++k) hf.z_m.push_back(height(random));
  hf.z_m[7] = std::numeric_limits<double>::quiet_NaN();  // node (1, 1): cells (0..1, 0..1)
  const Terrain t(hf, 0);
  std::uniform_real_distribution<double> x(99.0, 111.0), y(199.0, 211.0), offset(-0.5, 0.5);
  int below = 0, above = 0, outside = 0;
  for (int k = 0; k < 20000; ++k) {
    const double px = x(random), py = y(random);
    TerrainSample sample;
    const bool sampled = t.Sample(px, py, &sample);
    // Exactly at the height, just above and below it, and away from it.
    const double pz = !sampled     ? 0.0
                      : k % 4 == 0 ? sample.height_m
                      : k % 4 == 1 ? std::nextafter(sample.height_m, -1e300)
                      : k % 4 == 2 ? std::nextafter(sample.height_m, 1e300)
                                   : sample.height_m + offset(random);
    TerrainSample under;
    const bool is_below = t.SampleBelow(px, py, pz, &under);
    ASSERT_EQ(is_below, sampled && pz < sample.height_m) << px << " " << py << " " << pz;
    if (!sampled) {
      ++outside;
    } else if (is_below) {
      ++below;
      EXPECT_EQ(under.height_m, sample.height_m);
      EXPECT_EQ(under.normal, sample.normal);
    } else {
      ++above;
    }
  }
  // Every case was met many times (outside the grid and over the nodata node among them).
  EXPECT_GT(below, 3000);
  EXPECT_GT(above, 3000);
  EXPECT_GT(outside, 3000);
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
