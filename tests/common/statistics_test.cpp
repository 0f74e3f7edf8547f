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

}  // namespace
}  // namespace talus
