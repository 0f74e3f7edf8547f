// Per-rock random streams (solver/random.hpp): the contract that a rock's numbers depend on
// (seed, rock index) only, the 53-bit uniform, and orientations uniform on SO(3) by moments of the
// Haar measure that the rotated-z-axis test of simulate_test.cpp does not look at.

#include "solver/random.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace talus {
namespace {

// The first numbers of a stream are a function of (seed, rock index) alone: the same pair gives
// bit-identical numbers however the streams are interleaved, and both halves of both 64-bit
// arguments matter.
TEST(RockRandom, StreamIsAFunctionOfSeedAndRockIndexOnly) {
  std::vector<double> alone;
  RockRandom reference(42, 7);
  for (int k = 0; k < 100; ++k) alone.push_back(reference.Uniform());
  // Interleaved with other streams, created before and after it: the same numbers.
  RockRandom before(42, 6), same(42, 7), after(42, 8);
  for (int k = 0; k < 100; ++k) {
    before.Uniform();
    EXPECT_EQ(same.Uniform(), alone[k]) << k;
    after.Orientation();
  }
  const std::uint64_t high = std::uint64_t{1} << 32;
  const double first = RockRandom(0, 0).Uniform();
  for (const auto& [seed, rock] : std::array<std::pair<std::uint64_t, std::uint64_t>, 5>{
           {{high, 0}, {0, high}, {1, 0}, {0, 1}, {high + 1, high + 1}}}) {
    EXPECT_NE(RockRandom(seed, rock).Uniform(), first) << seed << ", " << rock;
  }
  // Seed and rock index are not interchangeable.
  EXPECT_NE(RockRandom(3, 5).Uniform(), RockRandom(5, 3).Uniform());
}

// "53 random bits, identical on every platform": each value is k 2^-53 for an integer k in
// [0, 2^53), and the stream is the top 53 bits of std::mt19937_64 seeded by std::seed_seq over the
// 32-bit halves (seed low, seed high, rock low, rock high): both algorithms are specified bit for
// bit by the standard, so this pins the stream to every conforming library.
TEST(RockRandom, UniformIsAMultipleOfTwoToTheMinus53InTheUnitInterval) {
  RockRandom r(1, 2);
  for (int k = 0; k < 10000; ++k) {
    const double u = r.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    const double scaled = std::ldexp(u, 53);
    ASSERT_EQ(scaled, std::floor(scaled)) << u;
  }
  std::seed_seq seq{1u, 0u, 2u, 0u};
  std::mt19937_64 engine(seq);
  RockRandom again(1, 2);
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(again.Uniform(), static_cast<double>(engine() >> 11) / 9007199254740992.0) << k;
}

// Uniformity of Uniform() by Pearson's chi-square over 20 equal bins of 100 000 draws (one stream):
// 19 degrees of freedom, whose 1e-6 upper quantile is 63.8; and its mean 1/2 and variance 1/12
// within 5 standard errors (sd of the mean sqrt(1/12 / n), of the sample variance sqrt(1/180 / n)).
TEST(RockRandom, UniformPassesChiSquareAndHasTheMomentsOfU01) {
  const int n = 100000, bins = 20;
  std::array<int, bins> count{};
  double sum = 0, sum2 = 0;
  RockRandom r(2024, 0);
  for (int k = 0; k < n; ++k) {
    const double u = r.Uniform();
    ++count[static_cast<std::size_t>(u * bins)];
    sum += u;
    sum2 += u * u;
  }
  double chi2 = 0;
  const double expected = static_cast<double>(n) / bins;
  for (int c : count) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 63.8);
  const double mean = sum / n, variance = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12 / n));
  EXPECT_NEAR(variance, 1.0 / 12, 5 * std::sqrt(1.0 / 180 / n));
}

// Neighbouring rocks' streams are uncorrelated: the correlation of the first draw of rock k with
// that of rock k + 1 (and of seed s with s + 1) over 20 000 pairs is within 5 / sqrt(n) of zero.
TEST(RockRandom, NeighbouringRocksAndSeedsAreUncorrelated) {
  const int n = 20000;
  auto correlation = [&](auto first, auto second) {
    double sx = 0, sy = 0, sxy = 0, sxx = 0, syy = 0;
    for (int k = 0; k < n; ++k) {
      const double x = first(k), y = second(k);
      sx += x, sy += y, sxy += x * y, sxx += x * x, syy += y * y;
    }
    const double cov = sxy / n - sx / n * sy / n;
    return cov / std::sqrt((sxx / n - sx / n * sx / n) * (syy / n - sy / n * sy / n));
  };
  EXPECT_NEAR(correlation([](int k) { return RockRandom(9, k).Uniform(); },
                          [](int k) { return RockRandom(9, k + 1).Uniform(); }),
              0.0, 5 / std::sqrt(n));
  EXPECT_NEAR(correlation([](int k) { return RockRandom(k, 3).Uniform(); },
                          [](int k) { return RockRandom(k + 1, 3).Uniform(); }),
              0.0, 5 / std::sqrt(n));
}

// Orientation() is a unit quaternion, and uniform on SO(3): under the Haar measure the unit
// quaternion (up to sign) is uniform on S^3, so E[q_i^2] = 1/4 (sd of q_i^2: 1/4) and
// E[q_i q_j] = 0 for i != j (sd 1/sqrt(24)); tr R = 1 + 2 cos(theta) = 4 w^2 - 1 has mean 0 and
// sd 1; and every rotated axis is uniform on S^2, so the rotated x and y axes have mean 0 (|mean|
// about 1/sqrt(n)) and second moments I / 3 (sd sqrt(4/45) on the diagonal, sqrt(1/15) off it).
// Tolerances: 5 standard errors over 20 000 rocks.
TEST(RockRandom, OrientationsHaveTheMomentsOfTheHaarMeasure) {
  const int n = 20000;
  const double se = 1 / std::sqrt(static_cast<double>(n));
  Eigen::Matrix4d second = Eigen::Matrix4d::Zero();
  double trace = 0;
  Eigen::Vector3d mean_x = Eigen::Vector3d::Zero(), mean_y = Eigen::Vector3d::Zero();
  Eigen::Matrix3d moment_x = Eigen::Matrix3d::Zero();
  for (int k = 0; k < n; ++k) {
    const Eigen::Quaterniond q = RockRandom(77, k).Orientation();
    ASSERT_NEAR(q.norm(), 1.0, 1e-15) << k;
    const Eigen::Vector4d c = q.coeffs();
    second += c * c.transpose() / n;
    const Eigen::Matrix3d r = q.toRotationMatrix();
    trace += r.trace() / n;
    mean_x += r.col(0) / n;
    mean_y += r.col(1) / n;
    moment_x += r.col(0) * r.col(0).transpose() / n;
  }
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      if (i == j) {
        EXPECT_NEAR(second(i, i), 0.25, 5 * 0.25 * se) << i;
      } else {
        EXPECT_NEAR(second(i, j), 0.0, 5 * se / std::sqrt(24.0)) << i << ", " << j;
      }
    }
  EXPECT_NEAR(trace, 0.0, 5 * se);
  EXPECT_LT(mean_x.norm(), 5 * se);
  EXPECT_LT(mean_y.norm(), 5 * se);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(moment_x(i, j), i == j ? 1.0 / 3 : 0.0,
                  5 * se * (i == j ? std::sqrt(4.0 / 45) : std::sqrt(1.0 / 15)))
          << i << ", " << j;
}

// Orientation() uses exactly three Uniform() draws (Shoemake's u1, u2, u3), so a rock's later
// numbers do not depend on how its orientation was drawn beyond that count: the fourth draw after an
// orientation is the fourth number of the stream.
TEST(RockRandom, OrientationConsumesThreeDraws) {
  RockRandom a(5, 5), b(5, 5);
  a.Orientation();
  for (int k = 0; k < 3; ++k) b.Uniform();
  EXPECT_EQ(a.Uniform(), b.Uniform());
}

}  // namespace
}  // namespace talus
