#include "common/column_statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/statistics.hpp"

namespace talus {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const std::vector<double> kPercents = {1, 5, 50, 90, 95, 99, 99.9, 100};

// Columns held in memory as a source, counting how often it is read.
struct Columns {
  std::vector<std::vector<double>> values;
  // Interleaved as the rows of a file: value i of every column, then value i + 1.
  ColumnSource Source(int* reads) const {
    return [this, reads](const ColumnSink& emit) {
      ++*reads;
      std::size_t longest = 0;
      for (const auto& v : values) longest = std::max(longest, v.size());
      for (std::size_t i = 0; i < longest; ++i)
        for (std::size_t c = 0; c < values.size(); ++c)
          if (i < values[c].size()) emit(c, values[c][i]);
    };
  }
};

bool SameNumber(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

// Every statistic against the in-memory definitions (Mean, NearestRankPercentile), bit for bit.
void ExpectBruteForce(const Columns& columns, std::size_t budget_bytes) {
  int reads = 0;
  const std::vector<ColumnStatistics> s =
      SummarizeColumns(columns.Source(&reads), columns.values.size(), kPercents, budget_bytes);
  ASSERT_EQ(s.size(), columns.values.size());
  for (std::size_t c = 0; c < s.size(); ++c) {
    const std::vector<double>& v = columns.values[c];
    SCOPED_TRACE("column " + std::to_string(c) + ", budget " + std::to_string(budget_bytes));
    EXPECT_EQ(s[c].count, static_cast<long>(v.size()));
    EXPECT_TRUE(SameNumber(s[c].mean(), Mean(v))) << s[c].mean() << " " << Mean(v);
    long finite = 0;
    for (double x : v) finite += std::isfinite(x) ? 1 : 0;
    EXPECT_EQ(s[c].finite, finite);
    EXPECT_TRUE(SameNumber(s[c].min, NearestRankPercentile(v, 1e-9)));
    EXPECT_TRUE(SameNumber(s[c].max, NearestRankPercentile(v, 100)));
    for (std::size_t k = 0; k < kPercents.size(); ++k)
      EXPECT_TRUE(SameNumber(s[c].percentiles[k], NearestRankPercentile(v, kPercents[k])))
          << "p" << kPercents[k] << ": " << s[c].percentiles[k] << " against "
          << NearestRankPercentile(v, kPercents[k]);
  }
}

Columns Awkward(std::size_t n, unsigned seed) {
  std::mt19937_64 random(seed);
  std::lognormal_distribution<double> runout(5, 1);
  std::normal_distribution<double> signed_value(0, 1e3);
  std::uniform_int_distribution<int> small(0, 3);
  Columns c;
  c.values.resize(5);
  for (std::size_t i = 0; i < n; ++i) {
    c.values[0].push_back(runout(random));        // positive, spread over binades
    c.values[1].push_back(signed_value(random));  // both signs
    c.values[2].push_back(small(random) - 1.5);   // few distinct values, many ties
    c.values[3].push_back(i % 7 == 0 ? (i % 2 ? -0.0 : 0.0) : 1 + 1e-15 * double(i % 3));
    if (i % 3 == 0) c.values[4].push_back(i % 6 == 0 ? NAN : (i % 9 == 0 ? kInf : 2.5 * i));
  }
  return c;
}

TEST(SummarizeColumns, EqualsTheInMemoryStatisticsForEveryBudget) {
  const Columns columns = Awkward(5000, 7);
  // From everything held (one reading) down to a budget below one histogram, which narrows every
  // percentile digit by digit down to the last bits.
  for (std::size_t budget : {std::size_t{1} << 20, std::size_t{200000}, std::size_t{40000},
                             std::size_t{8000}, std::size_t{64}, std::size_t{8}})
    ExpectBruteForce(columns, budget);
}

TEST(SummarizeColumns, ReadsTheSourceOnceWhenItsValuesFitTheBudget) {
  const Columns columns = Awkward(1000, 3);
  int reads = 0;
  SummarizeColumns(columns.Source(&reads), 5, kPercents, 1 << 20);
  EXPECT_EQ(reads, 1);
  reads = 0;
  // 12-bit digits: at most six histogram readings and one of the candidates per percentile batch.
  SummarizeColumns(columns.Source(&reads), 5, kPercents, 64);
  EXPECT_GT(reads, 1);
}

TEST(SummarizeColumns, ManyTiesAndFewDistinctValues) {
  Columns columns;
  columns.values.push_back(std::vector<double>(20000, 1.0));
  columns.values[0][123] = 0.5;
  columns.values[0][4567] = 3.0;
  columns.values.push_back(std::vector<double>(20000, -2.0));
  for (std::size_t budget : {std::size_t{1} << 20, std::size_t{1000}, std::size_t{8}})
    ExpectBruteForce(columns, budget);
}

TEST(SummarizeColumns, EmptyAndNonFiniteColumnsGiveNaN) {
  Columns columns;
  columns.values = {{}, {NAN, kInf}, {-kInf, 4.0}};
  for (std::size_t budget : {std::size_t{1} << 20, std::size_t{8}}) {
    int reads = 0;
    const auto s = SummarizeColumns(columns.Source(&reads), 3, {50, 100}, budget);
    EXPECT_EQ(s[0].count, 0);
    EXPECT_TRUE(std::isnan(s[0].mean()));
    EXPECT_TRUE(std::isnan(s[0].percentiles[0]));
    EXPECT_EQ(s[1].count, 2);
    EXPECT_EQ(s[1].finite, 0);
    EXPECT_TRUE(std::isnan(s[1].mean()));  // NaN is a value of the mean, as in Mean
    EXPECT_TRUE(std::isnan(s[1].min));
    EXPECT_TRUE(std::isnan(s[1].percentiles[1]));
    EXPECT_EQ(s[2].percentiles[0], 4.0);  // infinities are left out of the percentiles
    EXPECT_EQ(s[2].mean(), -kInf);
  }
}

TEST(SummarizeColumns, ValuesOfOtherColumnsAreIgnoredAndErrorsPropagate) {
  const ColumnSource extra = [](const ColumnSink& emit) {
    emit(0, 1.0);
    emit(7, 100.0);  // not a requested column
    emit(0, 3.0);
  };
  const auto s = SummarizeColumns(extra, 1, {50}, 8);
  EXPECT_EQ(s[0].count, 2);
  EXPECT_EQ(s[0].percentiles[0], 1.0);
  const ColumnSource failing = [](const ColumnSink& emit) {
    emit(0, 1.0);
    throw std::runtime_error("bad line");
  };
  EXPECT_THROW(SummarizeColumns(failing, 1, {50}), std::runtime_error);
}

// A file that changes between its readings (not one of a run) is an error, not a wrong value.
TEST(SummarizeColumns, ASourceThatChangesWhenReadAgainIsAnError) {
  int reads = 0;
  const ColumnSource changing = [&reads](const ColumnSink& emit) {
    const int n = 1000 + 10 * reads++;
    for (int i = 0; i < n; ++i) emit(0, i);
  };
  EXPECT_THROW(SummarizeColumns(changing, 1, {50}, 64), std::runtime_error);
  EXPECT_GT(reads, 1);
}

}  // namespace
}  // namespace talus
