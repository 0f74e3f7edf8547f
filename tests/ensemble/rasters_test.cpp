#include "ensemble/rasters.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>

#include "ensemble/runner.hpp"
#include "fixtures.hpp"

namespace talus::ensemble {
namespace {

const RasterLayer& Layer(const EnsembleReport& report, const std::string& name) {
  for (const RasterLayer& l : report.rasters)
    if (l.name == name) return l;
  throw std::runtime_error("no raster " + name);
}

int CellOf(const GridGeometry& g, double x, double y) {
  return static_cast<int>(std::lround((y - g.y0_m) / g.dy_m) * g.nx +
                          std::lround((x - g.x0_m) / g.dx_m));
}

// Cubes set down at rest on flat ground stay in their cell: there reach is the share of rocks
// released there, passages and deposits the count; every other cell is untouched.
TEST(Rasters, RocksAtRestOnAPlaneGiveTheKnownMaps) {
  Scene scene = testing::SmallPlane(0, 0, 20, 10);
  ReleaseSpec release = testing::PointRelease({{5, 0}, {12, 3}}, 3);
  release.height_m = 0.2;
  release.orientation = Eigen::Quaterniond::Identity();
  EnsembleOptions options;
  options.rasters = {scene.terrain.heights().grid, true, false, false, true, true, true};
  const EnsembleReport report = RunEnsemble(scene, release, options);
  ASSERT_EQ(report.count(EndReason::kRest), 6);
  const GridGeometry& g = scene.terrain.heights().grid;
  const int a = CellOf(g, 5, 0), b = CellOf(g, 12, 3);
  const auto& reach = Layer(report, "reach_probability").values;
  const auto& passages = Layer(report, "passages").values;
  const auto& deposits = Layer(report, "deposits").values;
  const auto& speed_max = Layer(report, "speed_max").values;
  for (int c = 0; c < g.nx * g.ny; ++c) {
    const bool hit = c == a || c == b;
    EXPECT_EQ(reach[c], hit ? 0.5f : 0.0f) << c;
    EXPECT_EQ(passages[c], hit ? 3.0f : 0.0f) << c;
    EXPECT_EQ(deposits[c], hit ? 3.0f : 0.0f) << c;
    if (hit)
      EXPECT_LT(speed_max[c], 0.02f);
    else
      EXPECT_EQ(speed_max[c], RasterLayer::kNoData);
  }
}

// Balls down a slope: every rock passes its release cell, deposits count the rocks at rest, and the
// statistics are ordered mean <= p95 <= max wherever a rock passed.
TEST(Rasters, SlopeRunsAreConsistent) {
  Scene scene = testing::SmallPlane(35, 15, 15);
  scene.rock = MakeRockShape(MakeIcosphere(0.2, 1), 2700);  // rolls down
  scene.options.max_time_s = 6;
  ReleaseSpec release = testing::PointRelease({{2, 0}}, 6);
  EnsembleOptions options;
  options.threads = 2;
  options.rasters = {scene.terrain.heights().grid, true, true, true, true, true, true};
  const EnsembleReport report = RunEnsemble(scene, release, options);
  const GridGeometry& g = scene.terrain.heights().grid;
  EXPECT_EQ(Layer(report, "passages").values[CellOf(g, 2, 0)], 6.0f);
  EXPECT_EQ(Layer(report, "reach_probability").values[CellOf(g, 2, 0)], 1.0f);
  const auto& deposits = Layer(report, "deposits").values;
  EXPECT_EQ(std::accumulate(deposits.begin(), deposits.end(), 0.0f),
            static_cast<float>(report.count(EndReason::kRest)));
  for (const char* q : {"speed", "energy", "jump_height"}) {
    const auto& mx = Layer(report, std::string(q) + "_max").values;
    const auto& mean = Layer(report, std::string(q) + "_mean").values;
    const auto& p95 = Layer(report, std::string(q) + "_p95").values;
    for (std::size_t c = 0; c < mx.size(); ++c) {
      if (mx[c] == RasterLayer::kNoData) continue;
      EXPECT_LE(mean[c], p95[c] * (1 + 1e-6f) + 1e-6f) << q << " " << c;
      EXPECT_LE(p95[c], mx[c]) << q << " " << c;
    }
  }
  // The path is continuous: every column of cells between the release and the furthest rock
  // was passed by some rock.
  const auto& passages = Layer(report, "passages").values;
  double reach_x = 0;
  for (int c = 0; c < g.nx * g.ny; ++c)
    if (passages[c] > 0) reach_x = std::max(reach_x, g.x0_m + (c % g.nx) * g.dx_m);
  EXPECT_GT(reach_x, 10);
  for (int i = 2; g.x0_m + i * g.dx_m <= reach_x; ++i) {
    bool column = false;
    for (int j = 0; j < g.ny; ++j) column = column || passages[j * g.nx + i] > 0;
    EXPECT_TRUE(column) << "column " << i;
  }
}

// The p95 rasters of a real run agree with the exact nearest-rank percentile of the values each
// rock left in each cell (its footprint), to within the stated bound (cell_summary.hpp).
TEST(Rasters, P95OfARunIsWithinTheStatedBoundOfTheExactPercentile) {
  Scene scene = testing::SmallPlane(35, 15, 15);
  scene.rock = MakeRockShape(MakeIcosphere(0.2, 1), 2700);
  scene.options.max_time_s = 6;
  ReleaseSpec release = testing::PointRelease({{2, 0}, {2, 3}}, 30);
  EnsembleOptions options;
  options.threads = 2;
  options.rasters = {scene.terrain.heights().grid, true, true, true, false, false, false};
  // Every value of every rock in every cell, from the footprints.
  struct Collect : RockSink {
    std::map<int, std::array<std::vector<float>, 3>> values;
    void OnRock(const RockOutcome& rock) override {
      const Footprint& f = rock.footprint;
      for (std::size_t k = 0; k < f.cells.size(); ++k) {
        auto& cell = values[f.cells[k]];
        cell[0].push_back(f.speed_m_s[k]);
        cell[1].push_back(f.energy_j[k]);
        cell[2].push_back(f.jump_height_m[k]);
      }
    }
  } sink;
  const EnsembleReport report = RunEnsemble(scene, release, options, &sink);
  const char* names[] = {"speed_p95", "energy_p95", "jump_height_p95"};
  int compared = 0, inside = 0;
  for (const auto& [cell, values] : sink.values) {
    for (int q = 0; q < 3; ++q) {
      std::vector<float> v = values[static_cast<std::size_t>(q)];
      const auto rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size())));
      std::nth_element(v.begin(), v.begin() + static_cast<long>(rank - 1), v.end());
      const double exact = v[rank - 1];
      const double raster = Layer(report, names[q]).values[static_cast<std::size_t>(cell)];
      EXPECT_LE(std::abs(raster - exact), ValueSummary::kRelativeError * std::abs(exact) + 1e-40)
          << names[q] << " cell " << cell << " of " << v.size() << " rocks";
      ++compared;
      inside += rank < v.size() ? 1 : 0;  // a rank inside the histogram, not the maximum
    }
  }
  EXPECT_GE(inside, 20);  // the comparison reaches the histogram, not only the exact extremes
  EXPECT_EQ(compared, 3 * static_cast<int>(sink.values.size()));
}

// The rocks of one run split between accumulators (as threads, ranks or parts would), merged in
// another order and passed through their serialized state, give the same rasters to the bit.
TEST(Rasters, AccumulatorsOfAnySplitMergeToTheSameRasters) {
  Scene scene = testing::SmallPlane(35, 15, 15);
  scene.rock = MakeRockShape(MakeIcosphere(0.2, 1), 2700);
  scene.options.max_time_s = 6;
  ReleaseSpec release = testing::PointRelease({{2, 0}, {2, 3}}, 6);
  EnsembleOptions options;
  options.rasters = {scene.terrain.heights().grid, true, true, true, true, true, true};
  struct Keep : RockSink {
    std::vector<Footprint> footprints;
    void OnRock(const RockOutcome& rock) override { footprints.push_back(rock.footprint); }
  } sink;
  const EnsembleReport whole = RunEnsemble(scene, release, options, &sink);
  ASSERT_EQ(sink.footprints.size(), 12u);
  RasterAccumulator a(options.rasters), b(options.rasters), c(options.rasters);
  for (std::size_t k = 0; k < 12; ++k)
    (k % 3 == 0 ? a : k % 3 == 1 ? b : c).Add(sink.footprints[k]);
  ByteWriter out;
  b.Serialize(out);
  const std::string bytes = out.Take();
  ByteReader in(bytes, "state of b");
  RasterAccumulator merged = RasterAccumulator::Deserialize(options.rasters, in);
  EXPECT_TRUE(in.at_end());
  merged.Merge(c);
  merged.Merge(a);
  EXPECT_EQ(merged.rocks(), 12);
  const std::vector<RasterLayer> layers = merged.Finish(scene.terrain.heights());
  ASSERT_EQ(layers.size(), whole.rasters.size());
  for (std::size_t l = 0; l < layers.size(); ++l)
    EXPECT_TRUE(layers[l].values == whole.rasters[l].values) << layers[l].name;
  // A state made for another grid or other rasters is refused.
  RasterRequest other = options.rasters;
  other.grid.nx += 1;
  ByteReader again(bytes, "state of b");
  EXPECT_THROW(RasterAccumulator::Deserialize(other, again), std::runtime_error);
  other = options.rasters;
  other.deposits = false;
  ByteReader third(bytes, "state of b");
  EXPECT_THROW(RasterAccumulator::Deserialize(other, third), std::runtime_error);
}

TEST(Rasters, P95IsTheNearestRankPercentile) {
  RasterRequest request;
  request.grid = {1, 1, 0, 0, 1, 1};
  request.speed = true;
  RasterAccumulator acc(request);
  for (int k = 1; k <= 40; ++k) {
    Footprint f;
    f.cells = {0};
    f.speed_m_s = {static_cast<float>(k)};
    acc.Add(f);
  }
  const auto layers = acc.Finish(Heightfield{request.grid, {0.0}});
  ASSERT_EQ(layers.size(), 3u);
  EXPECT_EQ(layers[0].values[0], 40.0f);  // max
  EXPECT_EQ(layers[1].values[0], 20.5f);  // mean
  // ceil(0.95 * 40) = 38th value, to within the summary's stated bound (cell_summary.hpp)
  EXPECT_NEAR(layers[2].values[0], 38.0f, 38.0 * ValueSummary::kRelativeError);
}

}  // namespace
}  // namespace talus::ensemble
