// Start designs: the Sobol sequence against its published first points, and the stratification
// that makes both designs space-filling.

#include "calibration/designs.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace talus::calibration {
namespace {

// Every coordinate of the n points has exactly one point in each of the n strata [k/n, (k+1)/n).
void ExpectStratified(const Eigen::MatrixXd& p) {
  const int n = static_cast<int>(p.rows());
  for (int j = 0; j < p.cols(); ++j) {
    std::vector<int> count(static_cast<std::size_t>(n), 0);
    for (int i = 0; i < n; ++i) {
      ASSERT_GE(p(i, j), 0);
      ASSERT_LT(p(i, j), 1);
      ++count[static_cast<std::size_t>(p(i, j) * n)];
    }
    for (int k = 0; k < n; ++k) EXPECT_EQ(count[static_cast<std::size_t>(k)], 1) << "column " << j;
  }
}

// The unscrambled sequence (SciPy's scipy.stats.qmc.Sobol(d=3, scramble=False) prints the same
// points): exact dyadic rationals, so compared exactly.
TEST(Sobol, FirstPointsAreThePublishedOnes) {
  const Eigen::MatrixXd p = Sobol(6, 3, 0);
  const double expected[6][3] = {{0, 0, 0},          {0.5, 0.5, 0.5},       {0.75, 0.25, 0.25},
                                 {0.25, 0.75, 0.75}, {0.375, 0.375, 0.625}, {0.875, 0.875, 0.125}};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(p(i, j), expected[i][j]) << i << ", " << j;
}

TEST(Sobol, PowersOfTwoAreStratifiedInEveryDimensionWithAndWithoutShift) {
  ExpectStratified(Sobol(64, kMaxSobolDimension, 0));
  ExpectStratified(Sobol(64, kMaxSobolDimension, 7));
  EXPECT_NE(Sobol(8, 2, 7), Sobol(8, 2, 8));  // the seed shifts
  EXPECT_EQ(Sobol(8, 2, 7), Sobol(8, 2, 7));  // deterministically
}

TEST(LatinHypercube, IsStratifiedAndDeterministic) {
  ExpectStratified(LatinHypercube(37, 5, 3));
  EXPECT_EQ(LatinHypercube(10, 3, 3), LatinHypercube(10, 3, 3));
  EXPECT_NE(LatinHypercube(10, 3, 3), LatinHypercube(10, 3, 4));
}

}  // namespace
}  // namespace talus::calibration
