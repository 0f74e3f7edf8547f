#include "ensemble/cell_summary.hpp"
#include "tests/portable_random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace talus::ensemble {
namespace {

// The nearest-rank q-quantile: the smallest value with at least q of the values at or below it.
float ExactQuantile(std::vector<float> values, double q) {
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(rank - 1), values.end());
  return values[rank - 1];
}

ValueSummary SummaryOf(const std::vector<float>& values) {
  ValueSummary s;
  for (float v : values) s.Add(v);
  return s;
}

std::string Bytes(const ValueSummary& s) {
  ByteWriter out;
  s.Serialize(out);
  return out.Take();
}

// Samples of the kinds of values the rasters see: speeds (uniform), energies over many decades
// (log-uniform), jump heights that can dip below zero (normal), and many repeated values.
std::vector<float> Sample(int kind, int n, std::mt19937_64& rng) {
  std::vector<float> v(static_cast<std::size_t>(n));
  talus::testing::UniformReal<double> uniform(0, 30);
  talus::testing::UniformReal<double> decades(-3, 9);
  talus::testing::Normal normal(0.5, 1.0);
  talus::testing::UniformInt few(1, 5);
  for (float& x : v) {
    switch (kind) {
      case 0:
        x = static_cast<float>(uniform(rng));
        break;
      case 1:
        x = static_cast<float>(std::pow(10.0, decades(rng)));
        break;
      case 2:
        x = static_cast<float>(normal(rng));
        break;
      default:
        x = static_cast<float>(few(rng)) * 0.1f;
        break;
    }
  }
  return v;
}

// The documented bound, |estimate - exact| <= 2^-(7 - L) |exact| at level L (+ 1e-40 below the
// normal floats), holds against the exact nearest-rank percentile for every kind and size of
// sample (the energies over 12 decades coarsen to level 4, the others stay at 0 or 1).
TEST(ValueSummary, QuantileIsWithinTheStatedBoundOfTheExactPercentile) {
  std::mt19937_64 rng(12);
  double worst = 0;
  for (int kind = 0; kind < 4; ++kind) {
    for (int n : {1, 2, 3, 19, 20, 21, 100, 1000, 20000}) {
      const std::vector<float> values = Sample(kind, n, rng);
      const ValueSummary s = SummaryOf(values);
      for (double q : {0.05, 0.5, 0.95, 1.0}) {
        const double exact = ExactQuantile(values, q);
        const double estimate = s.Quantile(q);
        const double error = std::abs(estimate - exact);
        EXPECT_LE(error, s.relative_error() * std::abs(exact) + 1e-40)
            << "kind " << kind << " n " << n << " q " << q << " exact " << exact;
        if (exact != 0 && s.level() == 0) worst = std::max(worst, error / std::abs(exact));
      }
    }
  }
  // The bound is not loose by orders of magnitude: the bins are as wide as stated.
  EXPECT_GT(worst, 0.25 * ValueSummary::kRelativeError);
}

TEST(ValueSummary, CountMinMaxAndMeanAreThoseOfTheValues) {
  std::mt19937_64 rng(3);
  const std::vector<float> values = Sample(2, 5000, rng);
  const ValueSummary s = SummaryOf(values);
  double sum = 0;
  for (float v : values) sum += v;
  EXPECT_EQ(s.count(), 5000);
  EXPECT_EQ(s.min(), *std::min_element(values.begin(), values.end()));
  EXPECT_EQ(s.max(), *std::max_element(values.begin(), values.end()));
  // Fixed point with a quantum of 2^-24 per value: the mean is within 2^-25 of the exact one.
  EXPECT_NEAR(s.mean(), sum / 5000, 0x1p-25 + 1e-12);
}

TEST(ValueSummary, EqualValuesGiveTheirValueExactly) {
  const ValueSummary s = SummaryOf(std::vector<float>(37, 3.3f));
  EXPECT_EQ(s.Quantile(0.95), 3.3f);
  EXPECT_EQ(s.max(), 3.3f);
}

TEST(ValueSummary, NonFiniteValuesAreLeftOut) {
  const ValueSummary s = SummaryOf({1.0f, NAN, INFINITY, 2.0f});
  EXPECT_EQ(s.count(), 2);
  EXPECT_EQ(s.max(), 2.0f);
}

// Bins follow the order of the values, negative and positive, across zero.
TEST(ValueSummary, BinsAreOrderedAsTheValues) {
  const std::vector<float> ordered = {-1e30f, -5.0f, -1e-3f, -1e-38f, 0.0f,
                                      1e-38f, 1e-3f, 5.0f,   1e30f};
  for (std::size_t k = 1; k < ordered.size(); ++k)
    EXPECT_LT(ValueSummary::BinOf(ordered[k - 1]), ValueSummary::BinOf(ordered[k])) << k;
  EXPECT_EQ(ValueSummary::BinOf(-0.0f), ValueSummary::BinOf(0.0f));
  std::mt19937_64 rng(4);
  std::vector<float> values = Sample(2, 10000, rng);
  std::sort(values.begin(), values.end());
  for (std::size_t k = 1; k < values.size(); ++k)
    ASSERT_LE(ValueSummary::BinOf(values[k - 1]), ValueSummary::BinOf(values[k])) << values[k];
}

// Any split of the values into parts, merged in any order, gives the same summary to the byte.
TEST(ValueSummary, MergingAnySplitInAnyOrderIsExact) {
  std::mt19937_64 rng(5);
  std::vector<float> values = Sample(1, 3000, rng);
  const std::vector<float> more = Sample(2, 3000, rng);
  values.insert(values.end(), more.begin(), more.end());
  const std::string whole = Bytes(SummaryOf(values));
  for (int parts : {2, 3, 7}) {
    std::vector<float> shuffled = values;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    std::vector<ValueSummary> pieces(static_cast<std::size_t>(parts));
    for (std::size_t k = 0; k < shuffled.size(); ++k)
      pieces[(k * 7919) % static_cast<std::size_t>(parts)].Add(shuffled[k]);
    ValueSummary merged;
    for (int k = parts - 1; k >= 0; --k) merged.Merge(pieces[static_cast<std::size_t>(k)]);
    EXPECT_EQ(Bytes(merged), whole) << parts << " parts";
  }
}

// The level is the smallest at which the values occupy at most kMaxBins bins, whatever their
// order: for values log-uniform over 2^-10 .. 2^20 (30 octaves, 1920 bins at level 0) that is
// level 3 (8 per octave, 240 bins; level 2 would need 480). Sorted, reversed and shuffled orders
// give the same bytes, and every quantile stays within the level's bound, 2^-4 (6.25 %).
TEST(ValueSummary, BinsAreCappedAtTheSmallestLevelThatFitsWhateverTheOrder) {
  std::mt19937_64 rng(21);
  talus::testing::UniformReal<double> octaves(-10, 20);
  std::vector<float> values(200000);
  for (float& v : values) v = static_cast<float>(std::exp2(octaves(rng)));
  const ValueSummary s = SummaryOf(values);
  EXPECT_EQ(s.level(), 3);
  EXPECT_LE(s.bins(), ValueSummary::kMaxBins);
  EXPECT_GT(s.bins(), ValueSummary::kMaxBins / 2);  // level 4 would have been too coarse
  EXPECT_DOUBLE_EQ(s.relative_error(), 1.0 / 16);
  std::vector<float> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(Bytes(SummaryOf(sorted)), Bytes(s));
  std::reverse(sorted.begin(), sorted.end());
  EXPECT_EQ(Bytes(SummaryOf(sorted)), Bytes(s));
  for (double q : {0.01, 0.05, 0.5, 0.95, 0.99}) {
    const double exact = ExactQuantile(values, q);
    EXPECT_LE(std::abs(s.Quantile(q) - exact), s.relative_error() * exact) << q;
  }
  // Merging parts at different levels (one narrow part stays at level 0) gives the same bytes.
  std::vector<float> narrow(values.begin(), values.begin() + 100);
  ValueSummary a = SummaryOf(narrow), b = SummaryOf({values.begin() + 100, values.end()});
  EXPECT_EQ(a.level(), 0);
  a.Merge(b);
  EXPECT_EQ(Bytes(a), Bytes(s));
}

// A million values fill at most the bins of their range: memory does not grow with the count.
TEST(ValueSummary, MemoryIsBoundedByTheRangeNotTheCount) {
  std::mt19937_64 rng(8);
  talus::testing::UniformReal<float> one_octave(1.0f, 2.0f);
  ValueSummary s;
  const float below_two = std::nextafter(2.0f, 0.0f);  // the distribution may return 2 itself
  for (int k = 0; k < 1000000; ++k) s.Add(std::min(one_octave(rng), below_two));
  EXPECT_LE(s.bins(), 64u);
  EXPECT_EQ(s.count(), 1000000);
}

TEST(ValueSummary, SerializedStateRoundTripsAndDamageIsAnError) {
  std::mt19937_64 rng(9);
  const ValueSummary s = SummaryOf(Sample(0, 500, rng));
  const std::string bytes = Bytes(s);
  ByteReader in(bytes, "state");
  const ValueSummary back = ValueSummary::Deserialize(in);
  EXPECT_TRUE(in.at_end());
  EXPECT_EQ(Bytes(back), bytes);
  EXPECT_EQ(back.Quantile(0.95), s.Quantile(0.95));
  const std::string cut = bytes.substr(0, bytes.size() - 3);
  ByteReader truncated(cut, "state");
  EXPECT_THROW(ValueSummary::Deserialize(truncated), std::runtime_error);
}

// Percentile(p) takes rank ceil(p n / 100) counted in integers: for the values 1 .. 100 the 7th
// percentile is the 7th value, where ceil(0.07 * 100) in doubles is 8 (0.07 * 100 rounds to
// 7.000000000000001); every integer percentile of 1 .. 100 is its own value, within the bound.
TEST(ValueSummary, PercentileIsTheIntegerNearestRank) {
  ValueSummary s;
  for (int k = 100; k >= 1; --k) s.Add(static_cast<float>(k));
  EXPECT_NEAR(s.Quantile(0.07), 8.0, 8.0 * ValueSummary::kRelativeError);  // the double's rank
  for (int p = 1; p <= 99; ++p)
    EXPECT_NEAR(s.Percentile(p), p, p * ValueSummary::kRelativeError) << p;
  EXPECT_EQ(s.Percentile(1), 1.0f);      // the smallest: exact
  EXPECT_EQ(s.Percentile(100), 100.0f);  // the largest: exact
}

}  // namespace
}  // namespace talus::ensemble
