#include "fieldobs/scores.hpp"
#include "tests/portable_random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace talus::fieldobs {
namespace {

// Random numbers that are the same with every standard library (tests/portable_random.hpp).
double Uniform01(std::mt19937_64& rng) { return talus::testing::Uniform01(rng); }
double StandardNormal(std::mt19937_64& rng) { return talus::testing::Normal()(rng); }
std::vector<double> NormalSample(std::mt19937_64& rng, int n, double mean, double sd) {
  std::vector<double> x(static_cast<size_t>(n));
  for (double& v : x) v = mean + sd * StandardNormal(rng);
  return x;
}

// The estimators' defining formulas, literally: O(n^2) over all ordered pairs.
double CrpsBruteForce(const std::vector<double>& x, double y) {
  const double n = static_cast<double>(x.size());
  double sum_abs = 0, sum_pairs = 0;
  for (double xi : x) sum_abs += std::abs(xi - y);
  for (double xi : x) {
    for (double xj : x) sum_pairs += std::abs(xi - xj);
  }
  return sum_abs / n - sum_pairs / (2 * n * (n - 1));
}
double EnergyBruteForce(const std::vector<Eigen::Vector2d>& x, const Eigen::Vector2d& y) {
  const double n = static_cast<double>(x.size());
  double sum_dist = 0, sum_pairs = 0;
  for (const auto& xi : x) sum_dist += (xi - y).norm();
  for (const auto& xi : x) {
    for (const auto& xj : x) sum_pairs += (xi - xj).norm();
  }
  return sum_dist / n - sum_pairs / (2 * n * (n - 1));
}
// The first term, (1/n) sum |x_i - y|: the magnitude the difference of the two terms is rounded
// against, so the scale of a relative tolerance (the score itself may be 0).
double MeanAbsoluteError(const std::vector<double>& x, double y) {
  double sum = 0;
  for (double xi : x) sum += std::abs(xi - y);
  return sum / static_cast<double>(x.size());
}

TEST(CrpsNormal, StandardNormalAtItsMeanByHand) {
  // Gneiting et al. (2005), Eq. 5 at z = 0: 2 phi(0) - 1/sqrt(pi) = (sqrt 2 - 1) / sqrt(pi)
  // = 0.23369497725510913... (also sqrt(2)/sqrt(pi) - 1/sqrt(pi)). Rounding only: 1e-12.
  EXPECT_NEAR(CrpsNormal(0, 1, 0), (std::numbers::sqrt2 - 1) * std::numbers::inv_sqrtpi, 1e-12);
  EXPECT_NEAR(CrpsNormal(0, 1, 0), 0.23369497725510913, 1e-12);
}

TEST(CrpsNormal, ScalesWithSdAndTendsToDistanceMinusHalfMeanPairDistance) {
  // CRPS is translation invariant and scales with sd: CRPS(N(m, s^2), m + s z) = s CRPS(N(0,1), z).
  for (double z : {-2.5, -0.3, 0.0, 1.0, 4.0}) {
    EXPECT_NEAR(CrpsNormal(7.5, 3.0, 7.5 + 3.0 * z), 3.0 * CrpsNormal(0, 1, z), 1e-12) << z;
  }
  // Far out, CRPS = E|X - y| - E|X - X'| / 2 -> |z| - 1/sqrt(pi) (E|X - X'| = 2/sqrt(pi));
  // phi(40) and erfc(40/sqrt 2) underflow to 0: exact to rounding, 1e-12 relative.
  EXPECT_NEAR(CrpsNormal(0, 1, 40), 40 - std::numbers::inv_sqrtpi, 40e-12);
  EXPECT_NEAR(CrpsNormal(0, 1, -40), 40 - std::numbers::inv_sqrtpi, 40e-12);
}

TEST(CrpsNormal, MatchesTheDefiningIntegral) {
  // CRPS(F, y) = integral of (F(t) - 1{t >= y})^2 dt (Matheson & Winkler 1976), by composite
  // Simpson on [m - 12 s, y] and [y, m + 12 s] (the integrand is smooth on each; the tails beyond
  // 12 sd contribute < 1e-30). Simpson's error with 20 000 intervals is ~1e-15; tolerance 1e-10.
  const double mean = 1.5, sd = 0.8;
  auto cdf = [&](double t) { return 0.5 * std::erfc(-(t - mean) / (sd * std::numbers::sqrt2)); };
  auto simpson = [](const std::function<double(double)>& f, double a, double b) {
    const int intervals = 20000;
    const double h = (b - a) / intervals;
    double sum = f(a) + f(b);
    for (int i = 1; i < intervals; ++i) sum += f(a + i * h) * (i % 2 ? 4 : 2);
    return sum * h / 3;
  };
  for (double y : {-1.0, 0.9, 1.5, 2.2, 4.0}) {
    const double lo = mean - 12 * sd, hi = mean + 12 * sd;
    const double integral = simpson([&](double t) { return cdf(t) * cdf(t); }, lo, y) +
                            simpson([&](double t) { return (1 - cdf(t)) * (1 - cdf(t)); }, y, hi);
    EXPECT_NEAR(CrpsNormal(mean, sd, y), integral, 1e-10) << "y = " << y;
  }
}

TEST(CrpsEnsemble, SmallCasesByHand) {
  // {0, 1}: (1/2)(|0-y| + |1-y|) - (1/(2*2*1)) * 2 = mean |x - y| - 1/2.
  const std::vector<double> two{0, 1};
  EXPECT_DOUBLE_EQ(CrpsEnsemble(two, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(CrpsEnsemble(two, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(CrpsEnsemble(two, 2.0), 1.0);  // (2 + 1)/2 - 1/2
  // {0, 1, 3}, y = 2: (2 + 1 + 1)/3 - (1 + 3 + 2) * 2 / (2*3*2) = 4/3 - 1 = 1/3 (the non-fair
  // ensemble CRPS, with 1/(2 n^2), would be 4/3 - 2/3 = 2/3).
  EXPECT_NEAR(CrpsEnsemble(std::vector<double>{3, 0, 1}, 2.0), 1.0 / 3, 1e-15);
  // One member: the absolute error.
  EXPECT_DOUBLE_EQ(CrpsEnsemble(std::vector<double>{3}, 1.0), 2.0);
  // All members equal: the two terms are |x - y| and 0.
  EXPECT_DOUBLE_EQ(CrpsEnsemble(std::vector<double>{4, 4, 4}, 1.0), 3.0);
}

TEST(CrpsEnsemble, EqualsBruteForceIncludingTies) {
  // The sorted O(n log n) form is an exact rewriting of the double sum: only rounding differs.
  // Tolerance 1e-12 relative to the first term (the score itself can be 0 by cancellation).
  // Members on a 0.5 grid give many ties; observations on the grid tie with members.
  std::mt19937_64 rng(20240611);
  for (int n : {2, 3, 17, 100}) {
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<double> x = NormalSample(rng, n, 10.0, 3.0);
      if (trial % 2 == 0) {
        for (double& v : x) v = std::round(2 * v) / 2;
      }
      for (double y : {x[0], 10.0, 10.25, -5.0, 40.0, x[static_cast<size_t>(n) - 1] + 1e-9}) {
        EXPECT_NEAR(CrpsEnsemble(x, y), CrpsBruteForce(x, y), 1e-12 * MeanAbsoluteError(x, y))
            << "n = " << n << ", trial " << trial << ", y = " << y;
      }
    }
  }
}

TEST(CrpsEnsemble, FairEstimatorConvergesToTheNormalClosedForm) {
  // n = 20 000 draws from N(3, 2^2) (fixed seed); the fair estimator is unbiased for
  // CrpsNormal(3, 2, y). Its standard error at n = 20 000, measured over 400 seeds:
  // 3.1e-3 (y = 3), 8.4e-3 (y = 4.5), 1.3e-2 (y = 0), 1.5e-2 (y = 9; about sd/sqrt(n), the
  // error of the mean, far out). Tolerance: 4 standard errors. Measured errors with this seed:
  // +4.3e-4, +2.2e-3, -1.3e-3, -2.0e-3 (0.14, 0.27, 0.10, 0.13 standard errors).
  struct Case {
    double y, standard_error;
  };
  const double mean = 3, sd = 2;
  std::mt19937_64 rng(7);
  const std::vector<double> x = NormalSample(rng, 20000, mean, sd);
  for (const Case& c : {Case{3, 3.1e-3}, Case{4.5, 8.4e-3}, Case{0, 1.3e-2}, Case{9, 1.5e-2}}) {
    EXPECT_NEAR(CrpsEnsemble(x, c.y), CrpsNormal(mean, sd, c.y), 4 * c.standard_error)
        << "y = " << c.y;
  }
}

TEST(CrpsEnsemble, NeverNegativeAndIndependentOfMemberOrder) {
  // Fair CRPS >= 0 by the triangle inequality; it is computed from a sorted copy, so a permuted
  // ensemble gives the same bits.
  std::mt19937_64 rng(3);
  std::vector<double> x = NormalSample(rng, 501, 1e6, 0.01);  // large offset, small spread
  const double crps = CrpsEnsemble(x, 1e6);
  std::shuffle(x.begin(), x.end(), rng);
  EXPECT_EQ(CrpsEnsemble(x, 1e6), crps);
  EXPECT_GE(crps, 0.0);
  EXPECT_DOUBLE_EQ(CrpsEnsemble(std::vector<double>{-1, 1}, 0.0), 0.0);
}

TEST(EnergyScore, ReducesToCrpsOnALine) {
  // On a line the Euclidean norm is the absolute value of the coordinate along it: ES = CRPS.
  // On the x axis the arithmetic is the same up to summation order; on a line at 30 degrees
  // through (5, -2) the rotation adds rounding of ~1e-16 per point. Tolerance 1e-12 relative
  // to the first term.
  std::mt19937_64 rng(11);
  const Eigen::Vector2d origin(5, -2),
      direction(std::cos(std::numbers::pi / 6), std::sin(std::numbers::pi / 6));
  for (int n : {1, 2, 3, 17, 100}) {
    const std::vector<double> s = NormalSample(rng, n, 0.0, 4.0);
    const double y = 1.3;
    std::vector<Eigen::Vector2d> on_axis, on_line;
    for (double si : s) {
      on_axis.emplace_back(si, 0.0);
      on_line.push_back(origin + si * direction);
    }
    const double crps = CrpsEnsemble(s, y);
    const double tolerance = 1e-12 * MeanAbsoluteError(s, y);
    EXPECT_NEAR(EnergyScore(on_axis, Eigen::Vector2d(y, 0)), crps, tolerance) << n;
    EXPECT_NEAR(EnergyScore(on_line, origin + y * direction), crps, tolerance) << n;
  }
}

TEST(EnergyScore, EqualsBruteForceAndSmallCasesByHand) {
  // The implementation sums pairs i < j once; the brute force all ordered pairs. Tolerance
  // 1e-12 relative to the first term.
  std::mt19937_64 rng(5);
  for (int n : {2, 3, 17, 100}) {
    std::vector<Eigen::Vector2d> x;
    for (int i = 0; i < n; ++i) x.emplace_back(StandardNormal(rng), 3 * StandardNormal(rng));
    const Eigen::Vector2d y(0.4, -1.0);
    double first = 0;
    for (const auto& xi : x) first += (xi - y).norm() / n;
    EXPECT_NEAR(EnergyScore(x, y), EnergyBruteForce(x, y), 1e-12 * first) << n;
  }
  // {(0,0), (3,4)} (members 5 apart): observed (0,0): (0 + 5)/2 - 5/2 = 0; observed (3,0):
  // distances 3 and 4, (3 + 4)/2 - 5/2 = 1; one member: the distance.
  const std::vector<Eigen::Vector2d> two{{0, 0}, {3, 4}};
  EXPECT_DOUBLE_EQ(EnergyScore(two, Eigen::Vector2d(0, 0)), 0.0);
  EXPECT_DOUBLE_EQ(EnergyScore(two, Eigen::Vector2d(3, 0)), 1.0);
  EXPECT_DOUBLE_EQ(EnergyScore(std::vector<Eigen::Vector2d>{{1, 1}}, Eigen::Vector2d(4, 5)), 5.0);
}

TEST(Pit, RankWithTiesByHand) {
  // {1, 2, 2, 2, 3}: n + 1 = 6 rank positions. y = 2: 1 below, 3 equal -> (1 + 4u)/6.
  const std::vector<double> x{2, 3, 2, 1, 2};
  EXPECT_DOUBLE_EQ(Pit(x, 2, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(Pit(x, 2, 0.0), 1.0 / 6);
  EXPECT_DOUBLE_EQ(Pit(x, 2, 0.75), 4.0 / 6);
  EXPECT_DOUBLE_EQ(Pit(x, 0, 0.5), 0.5 / 6);    // below every member
  EXPECT_DOUBLE_EQ(Pit(x, 9, 0.5), 5.5 / 6);    // above every member
  EXPECT_DOUBLE_EQ(Pit(x, 2.5, 0.0), 4.0 / 6);  // between, no tie
  EXPECT_DOUBLE_EQ(Pit(x, 9, 1.0), 1.0);        // u = 1 is accepted
}

// PIT values of `observations` observations, each with its own ensemble of `members` members;
// draw(rng, is_observation) gives one value.
template <typename Draw>
std::vector<double> PitSample(int observations, int members, Draw draw, bool randomise = true) {
  std::mt19937_64 rng(99);
  std::vector<double> pits;
  std::vector<double> ensemble(static_cast<size_t>(members));
  for (int k = 0; k < observations; ++k) {
    for (double& v : ensemble) v = draw(rng, false);
    const double y = draw(rng, true);
    pits.push_back(Pit(ensemble, y, randomise ? Uniform01(rng) : 0.5));
  }
  return pits;
}

TEST(Pit, UniformForObservationsFromTheModelAndNotForABiasedModel) {
  // 2 000 observations, 50 members each, chi-square test on 10 bins (200 expected per bin).
  // Same distribution: the PIT is exactly uniform, the test must pass at p > 0.001 (a false
  // alarm once in 1000 seeds). Model shifted by one sd: the PITs pile up low; measured
  // p ~ 0 (chi-square in the thousands), required p < 1e-6.
  // Continuous: N(0, 1). Discrete with many ties: Binomial(4, 1/2) (values 0..4, sd 1), where
  // only the randomisation over ties makes the PIT uniform; the mid-rank (u = 0.5 fixed) is not.
  // Measured with this seed: chi2 = 2.8 (p = 0.97) normal, 10.0 (p = 0.36) discrete; biased
  // 2089 and 1841 (p underflows to 0); mid-rank 631 (p ~ 6e-130).
  const int bins = 10;
  auto normal = [](double shift) {
    return [shift](std::mt19937_64& rng, bool observation) {
      return StandardNormal(rng) + (observation ? 0.0 : shift);
    };
  };
  auto binomial = [](double shift) {
    return [shift](std::mt19937_64& rng, bool observation) {
      const std::uint64_t bits = rng();
      const double heads = static_cast<double>(std::popcount(bits & 0xF));
      return heads + (observation ? 0.0 : shift);
    };
  };
  const PitHistogram normal_ok = MakePitHistogram(PitSample(2000, 50, normal(0.0)), bins);
  const PitHistogram normal_biased = MakePitHistogram(PitSample(2000, 50, normal(1.0)), bins);
  const PitHistogram discrete_ok = MakePitHistogram(PitSample(2000, 50, binomial(0.0)), bins);
  const PitHistogram discrete_biased = MakePitHistogram(PitSample(2000, 50, binomial(1.0)), bins);
  const PitHistogram discrete_mid_rank =
      MakePitHistogram(PitSample(2000, 50, binomial(0.0), /*randomise=*/false), bins);
  EXPECT_GT(normal_ok.p_value, 1e-3) << "chi2 = " << normal_ok.chi_square;
  EXPECT_GT(discrete_ok.p_value, 1e-3) << "chi2 = " << discrete_ok.chi_square;
  EXPECT_LT(normal_biased.p_value, 1e-6) << "chi2 = " << normal_biased.chi_square;
  EXPECT_LT(discrete_biased.p_value, 1e-6) << "chi2 = " << discrete_biased.chi_square;
  EXPECT_LT(discrete_mid_rank.p_value, 1e-6) << "chi2 = " << discrete_mid_rank.chi_square;
  EXPECT_EQ(normal_ok.degrees_of_freedom, 9);
}

TEST(PitHistogram, CountsChiSquareAndPValueByHand) {
  // Bins [0, 1/3), [1/3, 2/3), [2/3, 1]; counts {10, 20, 30}, expected 20 each:
  // chi2 = (100 + 0 + 100)/20 = 10 on 2 degrees of freedom, where the upper tail is exp(-chi2/2)
  // = exp(-5) exactly. Boost.Math to 1e-12 relative.
  std::vector<double> pits;
  for (int i = 0; i < 10; ++i) pits.push_back(0.0);
  for (int i = 0; i < 20; ++i) pits.push_back(0.5);
  for (int i = 0; i < 30; ++i) pits.push_back(1.0);  // 1 counts in the last bin
  const PitHistogram h = MakePitHistogram(pits, 3);
  EXPECT_EQ(h.counts, (std::vector<int>{10, 20, 30}));
  EXPECT_DOUBLE_EQ(h.chi_square, 10.0);
  EXPECT_EQ(h.degrees_of_freedom, 2);
  EXPECT_NEAR(h.p_value, std::exp(-5.0), 1e-12 * std::exp(-5.0));
  // One degree of freedom: the upper tail is erfc(sqrt(chi2/2)). Counts {3, 7}: chi2 = 1.6.
  const std::vector<double> two_bins{0.1, 0.2, 0.3, 0.6, 0.6, 0.7, 0.8, 0.9, 0.95, 0.5};
  const PitHistogram h2 = MakePitHistogram(two_bins, 2);
  EXPECT_EQ(h2.counts, (std::vector<int>{3, 7}));
  EXPECT_NEAR(h2.chi_square, 1.6, 1e-14);
  EXPECT_NEAR(h2.p_value, std::erfc(std::sqrt(0.8)), 1e-12);
  // One bin: no test.
  const PitHistogram h1 = MakePitHistogram(two_bins, 1);
  EXPECT_EQ(h1.counts, (std::vector<int>{10}));
  EXPECT_EQ(h1.degrees_of_freedom, 0);
  EXPECT_EQ(h1.p_value, 1.0);
}

TEST(Quantile, Type7ByHand) {
  // Type 7 (R's default): h = (n-1) p, x_(floor h) + frac(h) (x_(floor h + 1) - x_(floor h)).
  // Sorted {1, 2, 4, 8}: p = 0.05 -> h = 0.15 -> 1.15; p = 0.95 -> h = 2.85 -> 4 + 0.85 * 4 = 7.4;
  // p = 0.5 -> h = 1.5 -> 3. Rounding only: 1e-14.
  const std::vector<double> x{8, 1, 4, 2};
  EXPECT_NEAR(Quantile(x, 0.05), 1.15, 1e-14);
  EXPECT_NEAR(Quantile(x, 0.95), 7.4, 1e-14);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Quantile(x, 1.0), 8.0);
  EXPECT_DOUBLE_EQ(Quantile(std::vector<double>{2.5}, 0.95), 2.5);
}

TEST(ScoreScalar, FieldsOfAHandCheckedEnsemble) {
  // Members 0, 1, ..., 10 (shuffled), observed 9.7, u = 0.25.
  //   crps = (sum_k |k - 9.7|)/11 - (sum_{i<j} (j - i))/(11 * 10) = 52.3/11 - 220/110 = 30.3/11
  //   pit = (10 below + 0.25 (0 equal + 1)) / 12;  mean = median = 5;  sd = sqrt(110/10)
  //   q05 = 0.5, q95 = 9.5 (type 7, h = 0.5 and 9.5);  9.7 > q95: outside;  bias = 5 - 9.7.
  std::vector<double> x{3, 9, 0, 10, 5, 1, 7, 2, 8, 6, 4};
  const ScalarScore s = ScoreScalar(x, 9.7, 0.25);
  EXPECT_EQ(s.members, 11);
  EXPECT_EQ(s.observed, 9.7);
  EXPECT_NEAR(s.crps, 30.3 / 11, 1e-14);
  EXPECT_DOUBLE_EQ(s.pit, 10.25 / 12);
  EXPECT_DOUBLE_EQ(s.mean, 5.0);
  EXPECT_DOUBLE_EQ(s.median, 5.0);
  EXPECT_NEAR(s.sd, std::sqrt(11.0), 1e-14);
  EXPECT_DOUBLE_EQ(s.q05, 0.5);
  EXPECT_DOUBLE_EQ(s.q95, 9.5);
  EXPECT_FALSE(s.inside_90);
  EXPECT_NEAR(s.bias, -4.7, 1e-14);
  EXPECT_EQ(s.crps, CrpsEnsemble(x, 9.7));
  EXPECT_EQ(s.pit, Pit(x, 9.7, 0.25));

  // The 90 % interval is closed: its ends are inside.
  EXPECT_TRUE(ScoreScalar(x, 9.5, 0.25).inside_90);
  EXPECT_TRUE(ScoreScalar(x, 0.5, 0.25).inside_90);
  EXPECT_FALSE(ScoreScalar(x, 0.4999, 0.25).inside_90);

  // The report depends on the members as a multiset only, bit for bit.
  std::reverse(x.begin(), x.end());
  const ScalarScore r = ScoreScalar(x, 9.7, 0.25);
  EXPECT_EQ(r.crps, s.crps);
  EXPECT_EQ(r.mean, s.mean);
  EXPECT_EQ(r.sd, s.sd);

  // One member: sd 0, every quantile the member.
  const ScalarScore one = ScoreScalar(std::vector<double>{4}, 1, 0.5);
  EXPECT_EQ(one.members, 1);
  EXPECT_EQ(one.sd, 0.0);
  EXPECT_EQ(one.q05, 4.0);
  EXPECT_EQ(one.q95, 4.0);
  EXPECT_EQ(one.crps, 3.0);
  EXPECT_EQ(one.pit, 0.25);
}

TEST(SkillScore, AgainstAReference) {
  EXPECT_DOUBLE_EQ(SkillScore(0.5, 2.0), 0.75);
  EXPECT_DOUBLE_EQ(SkillScore(0.0, 2.0), 1.0);   // perfect
  EXPECT_DOUBLE_EQ(SkillScore(2.0, 2.0), 0.0);   // no better
  EXPECT_DOUBLE_EQ(SkillScore(3.0, 2.0), -0.5);  // worse
  EXPECT_TRUE(std::isnan(SkillScore(1.0, 0.0)));
  // The CRPS of a sharp, well-centred ensemble against the climatological spread.
  EXPECT_GT(SkillScore(CrpsNormal(0, 0.5, 0.1), CrpsNormal(0, 2.0, 0.1)), 0.0);
}

// Expects f to throw std::invalid_argument whose message contains every one of `parts`.
void ExpectInvalid(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one naming " << parts.front();
  } catch (const std::invalid_argument& e) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "'" << e.what() << "' does not contain '" << part << "'";
    }
  }
}

TEST(Scores, InvalidArgumentsThrowNamingTheArgumentAndValue) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> empty, ok{1, 2, 3}, bad{1, nan, 3};
  const std::vector<Eigen::Vector2d> empty2, ok2{{0, 0}, {1, 1}}, bad2{{0, 0}, {inf, 1}};

  ExpectInvalid([&] { CrpsEnsemble(empty, 1); }, {"CrpsEnsemble", "ensemble.size() = 0"});
  ExpectInvalid([&] { CrpsEnsemble(bad, 1); }, {"CrpsEnsemble", "ensemble[1] = nan"});
  ExpectInvalid([&] { CrpsEnsemble(ok, inf); }, {"CrpsEnsemble", "observed = inf"});

  ExpectInvalid([] { CrpsNormal(0, 0, 1); }, {"CrpsNormal", "sd = 0"});
  ExpectInvalid([] { CrpsNormal(0, -1.5, 1); }, {"CrpsNormal", "sd = -1.5"});
  ExpectInvalid([&] { CrpsNormal(0, inf, 1); }, {"CrpsNormal", "sd = inf"});
  ExpectInvalid([&] { CrpsNormal(nan, 1, 1); }, {"CrpsNormal", "mean = nan"});
  ExpectInvalid([&] { CrpsNormal(0, 1, -inf); }, {"CrpsNormal", "observed = -inf"});

  ExpectInvalid([&] { EnergyScore(empty2, Eigen::Vector2d(0, 0)); },
                {"EnergyScore", "ensemble.size() = 0"});
  ExpectInvalid([&] { EnergyScore(bad2, Eigen::Vector2d(0, 0)); },
                {"EnergyScore", "ensemble[1] = (inf, 1)"});
  ExpectInvalid([&] { EnergyScore(ok2, Eigen::Vector2d(0, nan)); },
                {"EnergyScore", "observed = (0, nan)"});

  ExpectInvalid([&] { Pit(empty, 1, 0.5); }, {"Pit", "ensemble.size() = 0"});
  ExpectInvalid([&] { Pit(bad, 1, 0.5); }, {"Pit", "ensemble[1] = nan"});
  ExpectInvalid([&] { Pit(ok, nan, 0.5); }, {"Pit", "observed = nan"});
  ExpectInvalid([&] { Pit(ok, 1, 1.25); }, {"Pit", "u = 1.25"});
  ExpectInvalid([&] { Pit(ok, 1, -0.5); }, {"Pit", "u = -0.5"});
  ExpectInvalid([&] { Pit(ok, 1, nan); }, {"Pit", "u = nan"});

  ExpectInvalid([&] { Quantile(empty, 0.5); }, {"Quantile", "ensemble.size() = 0"});
  ExpectInvalid([&] { Quantile(ok, 1.5); }, {"Quantile", "p = 1.5"});
  ExpectInvalid([&] { Quantile(ok, nan); }, {"Quantile", "p = nan"});

  ExpectInvalid([&] { ScoreScalar(empty, 1, 0.5); }, {"ScoreScalar", "ensemble.size() = 0"});
  ExpectInvalid([&] { ScoreScalar(bad, 1, 0.5); }, {"ScoreScalar", "ensemble[1] = nan"});
  ExpectInvalid([&] { ScoreScalar(ok, inf, 0.5); }, {"ScoreScalar", "observed = inf"});
  ExpectInvalid([&] { ScoreScalar(ok, 1, 2); }, {"ScoreScalar", "u = 2"});

  ExpectInvalid([&] { MakePitHistogram(ok, 0); }, {"MakePitHistogram", "bins = 0"});
  ExpectInvalid([&] { MakePitHistogram(ok, -3); }, {"MakePitHistogram", "bins = -3"});
  ExpectInvalid([&] { MakePitHistogram(empty, 10); }, {"MakePitHistogram", "pits.size() = 0"});
  ExpectInvalid(
      [&] {
        MakePitHistogram(std::vector<double>{0.5, 1.5}, 10);
      },
      {"MakePitHistogram", "pits[1] = 1.5"});
  ExpectInvalid([&] { MakePitHistogram(std::vector<double>{nan}, 10); },
                {"MakePitHistogram", "pits[0] = nan"});

  ExpectInvalid([&] { SkillScore(nan, 1); }, {"SkillScore", "score = nan"});
  ExpectInvalid([&] { SkillScore(1, inf); }, {"SkillScore", "reference_score = inf"});
}

// The leave-one-out climatologies are the scores of each value against all the others, as
// CrpsEnsemble and EnergyScore give them. Only rounding differs: the CRPS's prefix sums of values
// less their median err by about n eps (spread) per sum, so 1e-12 of the mean absolute error
// holds up to n ~ 10^3 with a wide margin (n eps = 2e-13 at n = 1000); the energy scores sum the
// same norms in another order. Ties (values on a 0.5 grid) and values far from the median
// (runouts near 1000 m) included.
TEST(LeaveOneOut, ScoresEachValueAgainstTheOthers) {
  std::mt19937_64 rng(20261126);
  for (int n : {2, 3, 4, 17, 200, 1000}) {
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<double> x = NormalSample(rng, n, trial == 2 ? 1000.0 : 10.0, 3.0);
      if (trial == 1)
        for (double& v : x) v = std::round(2 * v) / 2;
      const std::vector<double> loo = LeaveOneOutCrps(x);
      ASSERT_EQ(loo.size(), x.size());
      std::vector<Eigen::Vector2d> points;
      for (int k = 0; k < n; ++k) points.emplace_back(x[static_cast<std::size_t>(k)], 0.5 * k);
      const std::vector<double> loo_es =
          n <= 200 ? LeaveOneOutEnergyScores(points) : std::vector<double>();
      for (std::size_t k = 0; k < x.size(); ++k) {
        std::vector<double> others = x;
        others.erase(others.begin() + static_cast<std::ptrdiff_t>(k));
        EXPECT_NEAR(loo[k], CrpsEnsemble(others, x[k]), 1e-12 * MeanAbsoluteError(others, x[k]))
            << "n = " << n << ", trial " << trial << ", k = " << k;
        if (loo_es.empty()) continue;
        std::vector<Eigen::Vector2d> other_points = points;
        other_points.erase(other_points.begin() + static_cast<std::ptrdiff_t>(k));
        const double es = EnergyScore(other_points, points[k]);
        EXPECT_NEAR(loo_es[k], es, 1e-12 * (es + 1)) << "n = " << n << ", k = " << k;
      }
    }
  }
  EXPECT_TRUE(std::isnan(LeaveOneOutCrps(std::vector<double>{3.0})[0]));
  EXPECT_TRUE(LeaveOneOutCrps(std::vector<double>{}).empty());
}

// The validation of 40 000 observations took 34 s (a sorted copy of all the others per
// observation); 10^6 values now take well under a second (n log n).
TEST(LeaveOneOut, IsNotQuadratic) {
  std::mt19937_64 rng(7);
  const std::vector<double> x = NormalSample(rng, 1000000, 60, 10);
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<double> loo = LeaveOneOutCrps(x);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(loo.size(), x.size());
  // The quadratic form would take hours; 20 s leaves a wide margin for sanitizer builds and
  // loaded machines (0.5 s measured in a Release build on a loaded 2-core machine).
  EXPECT_LT(seconds, 20.0);
}

}  // namespace
}  // namespace talus::fieldobs
