#include "ensemble/raster_spill.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>
#include <vector>

#include "tests/portable_random.hpp"
#include "tests/test_tmp.hpp"

namespace talus::ensemble {
namespace {

namespace fs = std::filesystem;

constexpr float kUnset = -9999.0f;

// Passages of a 7 x 9 grid with two values each: most cells a few, one cell 3000 (more than a
// tiny budget holds), some none; values uniform, negative, repeated, -0, NaN and infinite.
struct Passages {
  std::vector<int> cells;
  std::vector<std::array<float, 2>> values;
};

Passages MakePassages() {
  std::mt19937_64 rng(17);
  talus::testing::UniformInt cell(0, 7 * 9 - 1);
  talus::testing::UniformReal<double> uniform(-5, 30);
  talus::testing::UniformInt kind(0, 9);
  Passages p;
  const auto value = [&]() {
    switch (kind(rng)) {
      case 0:
        return -0.0f;
      case 1:
        return 0.0f;
      case 2:
        return 2.5f;
      case 3:
        return NAN;
      case 4:
        return -INFINITY;
      default:
        return static_cast<float>(uniform(rng));
    }
  };
  for (int k = 0; k < 4000; ++k) {
    const int c = k < 3000 ? 40 : cell(rng);
    if (c == 12 || c == 13) continue;  // never passed
    p.cells.push_back(c);
    p.values.push_back({value(), static_cast<float>(uniform(rng))});
  }
  return p;
}

std::vector<int> CountsOf(const Passages& p) {
  std::vector<int> counts(7 * 9, 0);
  for (int c : p.cells) ++counts[static_cast<std::size_t>(c)];
  return counts;
}

// The nearest-rank percentile by brute force: sort the finite values, take rank ceil(p n / 100).
float BruteForce(std::vector<float> values, int percent) {
  values.erase(
      std::remove_if(values.begin(), values.end(), [](float v) { return !std::isfinite(v); }),
      values.end());
  if (values.empty()) return kUnset;
  std::sort(values.begin(), values.end());
  const std::size_t rank = (static_cast<std::size_t>(percent) * values.size() + 99) / 100;
  return values[rank - 1];
}

const GridGeometry kGrid{7, 9, 0, 0, 1, 1};
const std::vector<int> kPercents = {1, 7, 50, 95, 99, 100};

std::vector<std::vector<float>> PercentilesOf(RasterSpill& spill, const std::vector<int>& counts) {
  std::vector<std::vector<float>> out(2 * kPercents.size(), std::vector<float>(7 * 9, kUnset));
  spill.Percentiles(counts, kPercents, out);
  return out;
}

void ExpectBruteForce(const Passages& p, const std::vector<std::vector<float>>& out,
                      const std::string& what) {
  for (int cell = 0; cell < 7 * 9; ++cell)
    for (int v = 0; v < 2; ++v) {
      std::vector<float> values;
      for (std::size_t k = 0; k < p.cells.size(); ++k)
        if (p.cells[k] == cell) values.push_back(p.values[k][static_cast<std::size_t>(v)]);
      for (std::size_t k = 0; k < kPercents.size(); ++k) {
        const float got =
            out[static_cast<std::size_t>(v) * kPercents.size() + k][static_cast<std::size_t>(cell)];
        const float want = BruteForce(values, kPercents[k]);
        // The same bits: -0 is +0 in the spill.
        EXPECT_EQ(std::signbit(got), std::signbit(want == 0 ? 0.0f : want));
        EXPECT_EQ(got, want) << what << ": cell " << cell << " value " << v << " p" << kPercents[k];
      }
    }
}

// Whatever the memory budget (all at once, a few records: bands split by cells, and the cell of
// 3000 passages selected by radix passes; one record: every cell by radix), every percentile of
// every cell is the brute-force nearest-rank one, to the bit.
TEST(RasterSpill, PercentilesAreTheExactNearestRankForAnyBudget) {
  const Passages p = MakePassages();
  const std::vector<int> counts = CountsOf(p);
  for (std::size_t budget : {std::size_t{16} << 20, std::size_t{200}, std::size_t{1}}) {
    RasterSpill spill(kGrid, 2, {"", budget});
    for (std::size_t k = 0; k < p.cells.size(); ++k) spill.Append(p.cells[k], p.values[k].data());
    ExpectBruteForce(p, PercentilesOf(spill, counts), "budget " + std::to_string(budget));
  }
}

// The spill's directory is made at the first write, holds only band files and is removed with it.
TEST(RasterSpill, TheDirectoryIsRemovedWithTheSpill) {
  const fs::path dir = talus::testing::TestTmpRoot() / "raster_spill_dir";
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  {
    RasterSpill spill(kGrid, 1, {dir.string()});
    const float v = 1;
    spill.Append(3, &v);
    EXPECT_FALSE(fs::exists(dir));  // buffered
    std::vector<std::vector<float>> out(1, std::vector<float>(7 * 9, kUnset));
    std::vector<int> counts(7 * 9, 0);
    counts[3] = 1;
    spill.Percentiles(counts, {50}, out);
    EXPECT_EQ(out[0][3], 1.0f);
    EXPECT_TRUE(fs::is_directory(dir));
    RasterSpill moved(std::move(spill));
    EXPECT_TRUE(fs::is_directory(dir));  // the moved-from spill leaves it to the new one
  }
  EXPECT_FALSE(fs::exists(dir));
}

// Records written out and read into another spill (a part's, through partial.bin), or appended
// from another spill, give the same percentiles as one spill of all passages; a stream that ends
// early or puts a record in the wrong band is reported.
TEST(RasterSpill, SpillsMoveBetweenProcessesAndMergeExactly) {
  const Passages p = MakePassages();
  const std::vector<int> counts = CountsOf(p);
  RasterSpill a(kGrid, 2, {"", 200}), b(kGrid, 2, {}), c(kGrid, 2, {});
  for (std::size_t k = 0; k < p.cells.size(); ++k)
    (k % 3 == 0 ? a : k % 3 == 1 ? b : c).Append(p.cells[k], p.values[k].data());
  std::ostringstream written;
  b.WriteBands(written);
  EXPECT_EQ(written.str().size(), b.DiskBytes());
  std::vector<std::int64_t> records;
  for (int band = 0; band < b.bands(); ++band) records.push_back(b.records(band));
  std::istringstream in(written.str());
  EXPECT_EQ(a.ReadBands(in, records), "");
  a.Append(c);
  ExpectBruteForce(p, PercentilesOf(a, counts), "merged");

  RasterSpill d(kGrid, 2, {});
  std::istringstream cut(written.str().substr(0, written.str().size() - 5));
  EXPECT_EQ(d.ReadBands(cut, records), "they end early");
  std::string moved = written.str();
  moved[0] = static_cast<char>(60);  // the first record (of band 0) now of cell 60, band 8
  std::istringstream wrong(moved);
  RasterSpill e(kGrid, 2, {});
  EXPECT_NE(e.ReadBands(wrong, records).find("in band 0"), std::string::npos);
}

}  // namespace
}  // namespace talus::ensemble
