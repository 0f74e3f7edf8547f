#include "fieldobs/scores.hpp"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "common/format.hpp"
#include "common/statistics.hpp"

namespace talus::fieldobs {

namespace {

// Shortest text that reads back as the same double ("0.1", "nan", "-inf").
std::string Text(double value) { return RoundTrip(value); }
std::string Text(const Eigen::Vector2d& value) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "(" + std::string.
  std::string text = "(";
  text += Text(value.x());
  text += ", ";
  text += Text(value.y());
  text += ")";
  return text;
}

// Throws std::invalid_argument "<function>: <argument> = <value> <what>".
[[noreturn]] void Fail(const char* function, const std::string& argument, const std::string& value,
                       const char* what) {
  throw std::invalid_argument(std::string(function) + ": " + argument + " = " + value + " " + what);
}

void RequireFinite(const char* function, const char* argument, double value) {
  if (!std::isfinite(value)) Fail(function, argument, Text(value), "is not finite");
}

void RequireEnsemble(const char* function, std::span<const double> ensemble) {
  if (ensemble.empty()) Fail(function, "ensemble.size()", "0", "must be >= 1");
  for (size_t i = 0; i < ensemble.size(); ++i) {
    if (!std::isfinite(ensemble[i])) {
      Fail(function, "ensemble[" + std::to_string(i) + "]", Text(ensemble[i]), "is not finite");
    }
  }
}

void RequireUnitU(const char* function, double u) {
  if (!(u >= 0 && u <= 1)) Fail(function, "u", Text(u), "is not in [0, 1]");
}

std::vector<double> Sorted(std::span<const double> ensemble) {
  std::vector<double> sorted(ensemble.begin(), ensemble.end());
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

// Fair CRPS of a sorted, valid ensemble. The double sum over pairs is 2 sum_k k (n-k) gap_k: the
// gap between x_(k-1) and x_(k) lies between k (n-k) ordered pairs.
double CrpsSorted(const std::vector<double>& x, double y) {
  const size_t n = x.size();
  double sum_abs = 0;
  for (double xi : x) sum_abs += std::abs(xi - y);
  if (n == 1) return sum_abs;
  double sum_pairs = 0;  // sum over i < j of x_(j) - x_(i)
  for (size_t k = 1; k < n; ++k) {
    sum_pairs += static_cast<double>(k) * static_cast<double>(n - k) * (x[k] - x[k - 1]);
  }
  const double nd = static_cast<double>(n);
  const double crps = sum_abs / nd - sum_pairs / (nd * (nd - 1));
  // Never negative (triangle inequality); this only removes a rounding error.
  return std::max(crps, 0.0);
}

// Type-7 quantile of a sorted, non-empty ensemble.
double PitSorted(const std::vector<double>& x, double y, double u) {
  const auto below = std::lower_bound(x.begin(), x.end(), y);
  const auto above = std::upper_bound(below, x.end(), y);
  const double n_below = static_cast<double>(below - x.begin());
  const double n_equal = static_cast<double>(above - below);
  return (n_below + u * (n_equal + 1)) / static_cast<double>(x.size() + 1);
}

}  // namespace

double CrpsEnsemble(std::span<const double> ensemble, double observed) {
  RequireEnsemble("CrpsEnsemble", ensemble);
  RequireFinite("CrpsEnsemble", "observed", observed);
  return CrpsSorted(Sorted(ensemble), observed);
}

double CrpsNormal(double mean, double sd, double observed) {
  RequireFinite("CrpsNormal", "mean", mean);
  RequireFinite("CrpsNormal", "observed", observed);
  if (!(sd > 0 && std::isfinite(sd))) Fail("CrpsNormal", "sd", Text(sd), "must be > 0 and finite");
  const double z = (observed - mean) / sd;
  const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2 * std::numbers::pi);
  return sd * (z * std::erf(z / std::numbers::sqrt2) + 2 * pdf - std::numbers::inv_sqrtpi);
}

double EnergyScore(std::span<const Eigen::Vector2d> ensemble, const Eigen::Vector2d& observed) {
  if (ensemble.empty()) Fail("EnergyScore", "ensemble.size()", "0", "must be >= 1");
  for (size_t i = 0; i < ensemble.size(); ++i) {
    if (!ensemble[i].allFinite()) {
      Fail("EnergyScore", "ensemble[" + std::to_string(i) + "]", Text(ensemble[i]),
           "is not finite");
    }
  }
  if (!observed.allFinite()) Fail("EnergyScore", "observed", Text(observed), "is not finite");

  const size_t n = ensemble.size();
  double sum_dist = 0;
  for (const Eigen::Vector2d& x : ensemble) sum_dist += (x - observed).norm();
  if (n == 1) return sum_dist;
  double sum_pairs = 0;  // sum over i < j of |x_i - x_j|
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) sum_pairs += (ensemble[i] - ensemble[j]).norm();
  }
  const double nd = static_cast<double>(n);
  return std::max(sum_dist / nd - sum_pairs / (nd * (nd - 1)), 0.0);
}

std::vector<double> LeaveOneOutCrps(std::span<const double> values) {
  const std::size_t size = values.size();
  std::vector<double> out(size, std::numeric_limits<double>::quiet_NaN());
  if (size < 2) return out;
  RequireEnsemble("LeaveOneOutCrps", values);
  const std::vector<double> x = Sorted(values);
  // Prefix sums of the values less their median, which keeps them small (no cancellation of
  // large sums); the pairs' sum as in CrpsSorted.
  const double centre = x[size / 2];
  std::vector<double> prefix(size + 1, 0.0);
  for (std::size_t i = 0; i < size; ++i) prefix[i + 1] = prefix[i] + (x[i] - centre);
  double sum_pairs = 0;
  for (std::size_t k = 1; k < size; ++k)
    sum_pairs += static_cast<double>(k) * static_cast<double>(size - k) * (x[k] - x[k - 1]);
  const double n = static_cast<double>(size - 1);  // the others
  for (std::size_t k = 0; k < size; ++k) {
    const double y = values[k] - centre;
    const auto below =
        static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), values[k]) - x.begin());
    const auto above =
        static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), values[k]) - x.begin());
    // sum_i |x_i - y| over the others (the value itself adds 0).
    const double sum_abs = (y * static_cast<double>(below) - prefix[below]) +
                           ((prefix[size] - prefix[above]) - y * static_cast<double>(size - above));
    out[k] =
        size == 2 ? sum_abs : std::max(sum_abs / n - (sum_pairs - sum_abs) / (n * (n - 1)), 0.0);
  }
  return out;
}

std::vector<double> LeaveOneOutEnergyScores(std::span<const Eigen::Vector2d> points) {
  const std::size_t size = points.size();
  std::vector<double> out(size, std::numeric_limits<double>::quiet_NaN());
  if (size < 2) return out;
  for (std::size_t i = 0; i < size; ++i)
    if (!points[i].allFinite())
      Fail("LeaveOneOutEnergyScores", "points[" + std::to_string(i) + "]", Text(points[i]),
           "is not finite");
  std::vector<double> to_others(size, 0.0);  // sum_j |x_i - x_j|
  double sum_pairs = 0;                      // sum over i < j of |x_i - x_j|
  for (std::size_t i = 0; i < size; ++i)
    for (std::size_t j = i + 1; j < size; ++j) {
      const double d = (points[i] - points[j]).norm();
      to_others[i] += d;
      to_others[j] += d;
      sum_pairs += d;
    }
  const double n = static_cast<double>(size - 1);
  for (std::size_t k = 0; k < size; ++k)
    out[k] = size == 2
                 ? to_others[k]
                 : std::max(to_others[k] / n - (sum_pairs - to_others[k]) / (n * (n - 1)), 0.0);
  return out;
}

double Pit(std::span<const double> ensemble, double observed, double u) {
  RequireEnsemble("Pit", ensemble);
  RequireFinite("Pit", "observed", observed);
  RequireUnitU("Pit", u);
  return PitSorted(Sorted(ensemble), observed, u);
}

double Quantile(std::span<const double> ensemble, double p) {
  RequireEnsemble("Quantile", ensemble);
  if (!(p >= 0 && p <= 1)) Fail("Quantile", "p", Text(p), "is not in [0, 1]");
  return SortedQuantile(Sorted(ensemble), p);
}

ScalarScore ScoreScalar(std::span<const double> ensemble, double observed, double u) {
  RequireEnsemble("ScoreScalar", ensemble);
  RequireFinite("ScoreScalar", "observed", observed);
  RequireUnitU("ScoreScalar", u);
  const std::vector<double> x = Sorted(ensemble);
  const double n = static_cast<double>(x.size());

  ScalarScore s;
  s.members = static_cast<int>(x.size());
  s.observed = observed;
  s.crps = CrpsSorted(x, observed);
  s.pit = PitSorted(x, observed, u);

  // Mean and standard deviation in two passes (no cancellation for a large common offset).
  double sum = 0;
  for (double xi : x) sum += xi;
  s.mean = sum / n;
  double sum_sq = 0;
  for (double xi : x) sum_sq += (xi - s.mean) * (xi - s.mean);
  s.sd = x.size() > 1 ? std::sqrt(sum_sq / (n - 1)) : 0.0;

  s.median = SortedQuantile(x, 0.5);
  s.q05 = SortedQuantile(x, 0.05);
  s.q95 = SortedQuantile(x, 0.95);
  s.inside_90 = s.q05 <= observed && observed <= s.q95;
  s.bias = s.mean - observed;
  return s;
}

PitHistogram MakePitHistogram(std::span<const double> pits, int bins) {
  if (bins < 1) Fail("MakePitHistogram", "bins", std::to_string(bins), "must be >= 1");
  if (pits.empty()) Fail("MakePitHistogram", "pits.size()", "0", "must be >= 1");
  PitHistogram h;
  h.counts.assign(static_cast<size_t>(bins), 0);
  for (size_t i = 0; i < pits.size(); ++i) {
    const double pit = pits[i];
    if (!(pit >= 0 && pit <= 1)) {
      Fail("MakePitHistogram", "pits[" + std::to_string(i) + "]", Text(pit), "is not in [0, 1]");
    }
    const int bin = std::min(static_cast<int>(pit * bins), bins - 1);
    ++h.counts[static_cast<size_t>(bin)];
  }

  // Pearson's chi-square against equal expected counts.
  const double expected = static_cast<double>(pits.size()) / bins;
  for (int count : h.counts) h.chi_square += (count - expected) * (count - expected) / expected;
  h.degrees_of_freedom = bins - 1;
  if (h.degrees_of_freedom > 0) {
    const boost::math::chi_squared chi2(h.degrees_of_freedom);
    h.p_value = boost::math::cdf(boost::math::complement(chi2, h.chi_square));
  }
  return h;
}

double SkillScore(double score, double reference_score) {
  RequireFinite("SkillScore", "score", score);
  RequireFinite("SkillScore", "reference_score", reference_score);
  if (reference_score == 0) return std::numeric_limits<double>::quiet_NaN();
  return 1 - score / reference_score;
}

}  // namespace talus::fieldobs
