#include "common/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace talus {
namespace {

TEST(Statistics, NearestRankPercentiles) {
  // Nearest rank: the ceil(p/100 · n)-th smallest value (Hyndman & Fan 1996, definition 1).
  const std::vector<double> values = {5, 1, 4, 2, 3, 6, 8, 7, 10, 9};
  EXPECT_EQ(NearestRankPercentile(values, 50), 5);
  EXPECT_EQ(NearestRankPercentile(values, 95), 10);
  EXPECT_EQ(NearestRankPercentile(values, 90), 9);
  EXPECT_EQ(NearestRankPercentile(values, 1), 1);
  EXPECT_TRUE(std::isnan(NearestRankPercentile({}, 50)));
  EXPECT_EQ(NearestRankPercentile({NAN, 2}, 100), 2);  // NaN (no value) is left out
}

TEST(Statistics, MeanIsNanWithoutValues) {
  EXPECT_EQ(Mean({1, 2, 3, 6}), 3);
  EXPECT_EQ(Mean({0.1, 0.2, 0.3}), (0.1 + 0.2 + 0.3) / 3);  // summed in order
  EXPECT_TRUE(std::isnan(Mean({})));
}

TEST(Statistics, SortedQuantilesInterpolateBetweenOrderStatistics) {
  // Definition 7: h = (n - 1) p, between the floor(h)-th and the next (0-based).
  const std::vector<double> sorted = {1, 2, 4, 8, 16};
  EXPECT_EQ(SortedQuantile(sorted, 0), 1);
  EXPECT_EQ(SortedQuantile(sorted, 0.5), 4);
  EXPECT_EQ(SortedQuantile(sorted, 0.625), 6);  // h = 2.5
  EXPECT_EQ(SortedQuantile(sorted, 1), 16);
  EXPECT_EQ(SortedQuantile({7}, 0.9), 7);
}

}  // namespace
}  // namespace talus
