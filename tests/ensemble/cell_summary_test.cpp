#include "ensemble/cell_summary.hpp"
#include "tests/portable_random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace talus::ensemble {
namespace {

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
  EXPECT_EQ(s.min(), 3.3f);
  EXPECT_EQ(s.max(), 3.3f);
  EXPECT_NEAR(s.mean(), 3.3f, 0x1p-25);
}

TEST(ValueSummary, NonFiniteValuesAreLeftOut) {
  const ValueSummary s = SummaryOf({1.0f, NAN, INFINITY, 2.0f});
  EXPECT_EQ(s.count(), 2);
  EXPECT_EQ(s.max(), 2.0f);
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

// A summary is 32 bytes whatever the count: it holds no values.
TEST(ValueSummary, MemoryDoesNotGrowWithTheCount) {
  std::mt19937_64 rng(8);
  ValueSummary s;
  for (float v : Sample(0, 100000, rng)) s.Add(v);
  EXPECT_EQ(sizeof s, 32u);
  EXPECT_EQ(s.count(), 100000);
}

TEST(ValueSummary, SerializedStateRoundTripsAndDamageIsAnError) {
  std::mt19937_64 rng(9);
  const ValueSummary s = SummaryOf(Sample(0, 500, rng));
  const std::string bytes = Bytes(s);
  ByteReader in(bytes, "state");
  const ValueSummary back = ValueSummary::Deserialize(in);
  EXPECT_TRUE(in.at_end());
  EXPECT_EQ(Bytes(back), bytes);
  EXPECT_EQ(back.count(), s.count());
  EXPECT_EQ(back.mean(), s.mean());
  const std::string cut = bytes.substr(0, bytes.size() - 3);
  ByteReader truncated(cut, "state");
  EXPECT_THROW(ValueSummary::Deserialize(truncated), std::runtime_error);
}

}  // namespace
}  // namespace talus::ensemble
