#include "common/rounding.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace talus {
namespace {

// RoundHalfAway stands in for std::lround in grid lookups, so it must give lround's result for
// every finite value below 2^62, halves and their neighbours above all (exact: integers).
TEST(Rounding, RoundHalfAwayIsLround) {
  std::vector<double> values = {0.0,
                                -0.0,
                                0.5,
                                -0.5,
                                1.5,
                                -1.5,
                                2.5,
                                -2.5,
                                0.49999999999999994,
                                -0.49999999999999994,
                                4503599627370495.5,
                                -4503599627370495.5,
                                0x1p52,
                                0x1p52 + 1,
                                -0x1p52 - 3,
                                0x1p61,
                                -0x1p61,
                                0x1p62 - 1024};
  for (int k = -1000; k <= 1000; ++k) {
    const double half = k + 0.5;
    values.push_back(half);
    values.push_back(std::nextafter(half, -1e300));
    values.push_back(std::nextafter(half, 1e300));
    values.push_back(k);
  }
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> small(-3000.0, 3000.0), large(-1e15, 1e15);
  for (int i = 0; i < 100000; ++i) {
    values.push_back(small(random));
    values.push_back(large(random));
  }
  for (const double x : values) ASSERT_EQ(RoundHalfAway(x), std::lround(x)) << x;
}

// What no grid holds: NaN, infinities and values from 2^62 on give LONG_MIN, which every lookup
// takes for outside.
TEST(Rounding, RoundHalfAwayPutsNonFiniteAndHugeValuesOutside) {
  constexpr long kOutside = std::numeric_limits<long>::min();
  EXPECT_EQ(RoundHalfAway(std::numeric_limits<double>::quiet_NaN()), kOutside);
  EXPECT_EQ(RoundHalfAway(std::numeric_limits<double>::infinity()), kOutside);
  EXPECT_EQ(RoundHalfAway(-std::numeric_limits<double>::infinity()), kOutside);
  EXPECT_EQ(RoundHalfAway(0x1p62), kOutside);
  EXPECT_EQ(RoundHalfAway(-0x1p62), kOutside);
  EXPECT_EQ(RoundHalfAway(1e300), kOutside);
}

}  // namespace
}  // namespace talus
