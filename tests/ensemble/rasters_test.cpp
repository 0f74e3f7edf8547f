#include "ensemble/rasters.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

#include "ensemble/runner.hpp"
#include "fixtures.hpp"
#include "tests/test_tmp.hpp"

namespace talus::ensemble {
namespace {

const RasterLayer& Layer(const std::vector<RasterLayer>& layers, const std::string& name) {
  for (const RasterLayer& l : layers)
    if (l.name == name) return l;
  throw std::runtime_error("no raster " + name);
}

const RasterLayer& Layer(const EnsembleReport& report, const std::string& name) {
  return Layer(report.rasters, name);
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

// The percentile rasters of a real run are the exact nearest-rank percentile (rank
// ceil(p n / 100) of the n values, counted in integers) of the values each rock left in each cell
// (its footprint), to the bit, with the default memory for reading the spill back and with a tiny
// one (a few records at a time: the bands are split by cells, and cells with more passages than
// that are selected in radix passes). 7 is a percentile whose rank a floating-point 0.07 n would
// put one too high for some n.
TEST(Rasters, PercentilesOfARunAreTheExactPercentiles) {
  Scene scene = testing::SmallPlane(35, 15, 15);
  scene.rock = MakeRockShape(MakeIcosphere(0.2, 1), 2700);
  scene.options.max_time_s = 6;
  ReleaseSpec release = testing::PointRelease({{2, 0}, {2, 3}}, 30);
  EnsembleOptions options;
  options.threads = 2;
  options.rasters = {scene.terrain.heights().grid, true, true, true, false, false, false};
  options.rasters.percentiles = {7, 50, 90, 95, 99};
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
  };
  for (std::size_t memory_bytes : {std::size_t{16} << 20, std::size_t{100}}) {
    options.raster_spill.memory_bytes = memory_bytes;
    Collect sink;
    const EnsembleReport report = RunEnsemble(scene, release, options, &sink);
    ASSERT_EQ(report.rasters.size(), 3u * (2 + 5));
    const char* quantities[] = {"speed", "energy", "jump_height"};
    int compared = 0, inside = 0, crowded = 0;
    for (const auto& [cell, values] : sink.values) {
      crowded += values[0].size() * 12 > memory_bytes ? 1 : 0;
      for (int q = 0; q < 3; ++q) {
        for (int p : options.rasters.percentiles) {
          std::vector<float> v = values[static_cast<std::size_t>(q)];
          std::sort(v.begin(), v.end());
          const std::size_t rank = (static_cast<std::size_t>(p) * v.size() + 99) / 100;
          const std::string name = std::string(quantities[q]) + "_p" + std::to_string(p);
          EXPECT_EQ(Layer(report, name).values[static_cast<std::size_t>(cell)], v[rank - 1])
              << name << " cell " << cell << " of " << v.size() << " rocks, memory "
              << memory_bytes;
          ++compared;
          inside += rank > 1 && rank < v.size() ? 1 : 0;  // not an extreme
        }
      }
    }
    EXPECT_GE(inside, 100);  // the comparison reaches inner ranks, not only the extremes
    EXPECT_EQ(compared, 3 * 5 * static_cast<int>(sink.values.size()));
    if (memory_bytes < 1000) {
      EXPECT_GE(crowded, 10);  // cells beyond the memory: radix passes
    }
  }
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
  std::ostringstream spilled;
  b.WriteSpill(spilled);
  const std::string bytes = out.Take();
  ByteReader in(bytes, "state of b");
  RasterAccumulator merged(options.rasters);
  std::istringstream spill(spilled.str());
  merged.MergeSerialized(in, spill);
  EXPECT_TRUE(in.at_end());
  EXPECT_EQ(spill.peek(), std::istringstream::traits_type::eof());
  merged.Merge(c);
  merged.Merge(a);
  EXPECT_EQ(merged.rocks(), 12);
  const std::vector<RasterLayer> layers = merged.Finish(scene.terrain.heights());
  ASSERT_EQ(layers.size(), whole.rasters.size());
  for (std::size_t l = 0; l < layers.size(); ++l)
    EXPECT_TRUE(layers[l].values == whole.rasters[l].values) << layers[l].name;
  // A state made for another grid or other rasters is refused, as is one whose spill ends early.
  const auto merge = [&](const RasterRequest& request, const std::string& values) {
    ByteReader head(bytes, "state of b");
    std::istringstream stream(values);
    RasterAccumulator(request).MergeSerialized(head, stream);
  };
  RasterRequest other = options.rasters;
  other.grid.nx += 1;
  EXPECT_THROW(merge(other, spilled.str()), std::runtime_error);
  other = options.rasters;
  other.deposits = false;
  EXPECT_THROW(merge(other, spilled.str()), std::runtime_error);
  EXPECT_THROW(merge(options.rasters, spilled.str().substr(0, spilled.str().size() - 1)),
               std::runtime_error);
  // The state records its percentiles: a part run for other ones is refused, naming both.
  other = options.rasters;
  other.percentiles = {50, 95};
  try {
    merge(other, spilled.str());
    FAIL() << "other percentiles accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "state of b holds other percentiles (p95) than the scene asks for (p50, p95)"),
              std::string::npos)
        << e.what();
  }
}

// The values behind the percentiles are spilled into the directory the options name, and it is
// gone when the run ends, whether it succeeded or a sink's exception stopped it.
TEST(Rasters, TheSpillIsRemovedAfterTheRunAndAfterAFailure) {
  namespace fs = std::filesystem;
  Scene scene = testing::SmallPlane(35, 15, 15);
  ReleaseSpec release = testing::PointRelease({{2, 0}}, 6);
  const fs::path parent = talus::testing::TestTmpRoot() / "rasters_spill";
  fs::remove_all(parent);
  fs::create_directories(parent);
  EnsembleOptions options;
  options.rasters = {scene.terrain.heights().grid, true, true, true, true, true, true};
  options.raster_spill.dir = (parent / "spill").string();
  struct Seen : RockSink {
    long rocks = 0;
    void OnRock(const RockOutcome&) override { ++rocks; }
  } seen;
  const EnsembleReport report = RunEnsemble(scene, release, options, &seen);
  EXPECT_EQ(seen.rocks, 6);
  EXPECT_NE(Layer(report, "speed_p95").values[CellOf(scene.terrain.heights().grid, 2, 0)],
            RasterLayer::kNoData);
  EXPECT_TRUE(fs::is_empty(parent));
  struct Fail : RockSink {
    void OnRock(const RockOutcome& rock) override {
      if (rock.rock == 3) throw std::runtime_error("stop");
    }
  } fail;
  EXPECT_THROW(RunEnsemble(scene, release, options, &fail), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(parent));
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
  EXPECT_EQ(layers[2].values[0], 38.0f);  // ceil(0.95 * 40) = 38th value
}

// Where the DEM has nodata every raster is nodata, whatever the rocks left there; elsewhere the
// counts are 0 and the statistics nodata where no rock passed.
TEST(Rasters, NodataInTheDemIsNodataInEveryRaster) {
  RasterRequest request{{3, 2, 0, 0, 1, 1}, true, true, true, true, true, true};
  request.percentiles = {50, 95};
  Heightfield dem{request.grid, {1, 1, 1, 1, std::nan(""), 1}};  // cell 4 (i = 1, j = 1) is a hole
  RasterAccumulator acc(request);
  for (int rock = 0; rock < 2; ++rock) {
    Footprint f;
    f.cells = {0, 4};  // a rock passes the hole (its centre of mass may be in a nodata cell)
    f.speed_m_s = {2, 3};
    f.energy_j = {20, 30};
    f.jump_height_m = {0.5, 0.25};
    f.deposit_cell = 4;
    acc.Add(f);
  }
  const std::vector<RasterLayer> layers = acc.Finish(dem);
  ASSERT_EQ(layers.size(), 3u * 4 + 3);
  for (const RasterLayer& l : layers) {
    EXPECT_EQ(l.values[4], RasterLayer::kNoData) << l.name;
    const bool count = l.statistic == "count" || l.statistic == "fraction";
    for (std::size_t c : {1u, 2u, 3u, 5u})  // valid, no rock passed
      EXPECT_EQ(l.values[c], count ? 0.0f : RasterLayer::kNoData) << l.name << " " << c;
  }
  EXPECT_EQ(Layer(layers, "passages").values[0], 2.0f);
  EXPECT_EQ(Layer(layers, "reach_probability").values[0], 1.0f);
  EXPECT_EQ(Layer(layers, "deposits").values[0], 0.0f);
  EXPECT_EQ(Layer(layers, "speed_p50").values[0], 2.0f);  // every value the same
  EXPECT_EQ(Layer(layers, "jump_height_max").values[0], 0.5f);
}

// Each raster says what it is: name, quantity, statistic, unit and a description with the
// percentile's ordinal.
TEST(Rasters, LayersAreNamedAndDescribedInOrder) {
  RasterRequest request{{1, 1, 0, 0, 1, 1}, false, true, false, true, true, true};
  request.percentiles = {1, 2, 3, 11, 12, 13, 21, 22, 23, 99};
  RasterAccumulator acc(request);
  const std::vector<RasterLayer> layers = acc.Finish(Heightfield{request.grid, {0.0}});
  std::vector<std::string> names, descriptions;
  for (const RasterLayer& l : layers) {
    names.push_back(l.name);
    descriptions.push_back(l.description);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"energy_max", "energy_mean", "energy_p1", "energy_p2",
                                             "energy_p3", "energy_p11", "energy_p12", "energy_p13",
                                             "energy_p21", "energy_p22", "energy_p23", "energy_p99",
                                             "passages", "deposits", "reach_probability"}));
  EXPECT_EQ(descriptions[0], "energy, largest over passing rocks");
  EXPECT_EQ(descriptions[1], "energy, mean over passing rocks");
  for (auto [k, ordinal] : {std::pair{2, "1st"},
                            {3, "2nd"},
                            {4, "3rd"},
                            {5, "11th"},
                            {6, "12th"},
                            {7, "13th"},
                            {8, "21st"},
                            {9, "22nd"},
                            {10, "23rd"},
                            {11, "99th"}})
    EXPECT_EQ(descriptions[static_cast<std::size_t>(k)],
              std::string("energy, ") + ordinal + " percentile over passing rocks");
  EXPECT_EQ(layers[4].quantity, "energy");
  EXPECT_EQ(layers[4].statistic, "p3");
  EXPECT_EQ(layers[4].unit, "J");
  EXPECT_EQ(layers[12].unit, "count");
  EXPECT_EQ(layers[12].statistic, "count");
  EXPECT_EQ(layers[13].unit, "count");
  EXPECT_EQ(layers[14].unit, "1");
  EXPECT_EQ(layers[14].statistic, "fraction");
  EXPECT_EQ(descriptions[14], "reach probability, fraction of all rocks that passed the cell");
}

// Each raster kind has its name (the one list that scenes, summary.json and the file names read)
// and its own flag of the request.
TEST(RasterRequest, EveryKindHasItsNameAndItsOwnFlag) {
  EXPECT_EQ(kRasterKindNames.List(),
            "speed, energy, jump_height, passages, deposits, reach_probability, tree_hits");
  for (int k = 0; k < kRasterKindNames.size(); ++k) {
    const auto kind = static_cast<RasterKind>(k);
    EXPECT_STREQ(ToString(kind), kRasterKindNames.Name(k));
    RasterRequest request;
    EXPECT_FALSE(request.any());
    request.Wants(kind) = true;
    EXPECT_TRUE(request.any()) << ToString(kind);
    for (int other = 0; other < kRasterKindNames.size(); ++other)
      EXPECT_EQ(std::as_const(request).Wants(static_cast<RasterKind>(other)), other == k)
          << ToString(kind) << " sets " << kRasterKindNames.Name(other);
  }
  RasterRequest request;
  request.jump_height = true;
  EXPECT_TRUE(request.Wants(RasterKind::kJumpHeight));
}

TEST(RasterRequest, PercentilesAreAscendingIntegersInOneToNinetyNine) {
  RasterRequest request;
  std::string why;
  EXPECT_TRUE(request.IsValid(&why)) << why;  // the defaults
  EXPECT_EQ(request.percentiles, std::vector<int>{95});
  request.percentiles = {1, 50, 99};
  EXPECT_TRUE(request.IsValid(&why)) << why;
  request.percentiles = {95, 50};
  EXPECT_FALSE(request.IsValid(&why));
  EXPECT_EQ(why, "percentiles = 50 must be ascending without repeats");
  request.percentiles = {0};
  EXPECT_FALSE(request.IsValid(&why));
  EXPECT_EQ(why, "percentiles = 0 must each be in 1 .. 99");
  request.percentiles = {100};
  EXPECT_FALSE(request.IsValid(&why));
}

}  // namespace
}  // namespace talus::ensemble
