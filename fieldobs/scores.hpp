#pragma once
// Proper scores of an ensemble of simulated rocks (the predictive distribution) against one field
// observation: CRPS, energy score, the probability integral transform (PIT) and its uniformity
// test, and a summary report per scalar observation.
//
// Invalid arguments (an empty ensemble, non-finite values, sd <= 0, bins < 1, u outside [0, 1])
// are programming errors of the caller, who validates user input first; they throw
// std::invalid_argument with a message naming the function, the argument and its value.
// Everything is deterministic. Functions of a scalar ensemble work on a sorted copy, so their
// results depend on the ensemble as a multiset only, bit for bit, not on the members' order.

#include <Eigen/Core>
#include <span>
#include <vector>

namespace talus::fieldobs {

// Continuous ranked probability score of an observation y against an ensemble x_1..x_n, the fair
// (unbiased) estimator of the CRPS of the distribution the ensemble is drawn from (Ferro 2014;
// Zamo & Naveau 2018):
//   CRPS_fair = (1/n) sum_i |x_i - y| - 1/(2 n (n-1)) sum_i sum_j |x_i - x_j|,
// in the unit of the observation; 0 is perfect and it is never negative. The double sum is taken
// in O(n log n) from the sorted ensemble as 2 sum_k k (n-k) (x_(k) - x_(k-1)), a sum of
// non-negative terms. For n == 1 it is |x_1 - y|.
double CrpsEnsemble(std::span<const double> ensemble, double observed);

// CRPS of a normal predictive distribution N(mean, sd^2), closed form (Gneiting et al. 2005):
//   sd [z erf(z / sqrt 2) + 2 phi(z) - 1 / sqrt(pi)],  z = (observed - mean) / sd.
// Requires sd > 0.
double CrpsNormal(double mean, double sd, double observed);

// Energy score of a 2-D observation (e.g. a deposit position, m) against an ensemble, fair form
// (Gneiting & Raftery 2007):
//   ES = (1/n) sum_i |x_i - y| - 1/(2 n (n-1)) sum_i sum_j |x_i - x_j|,  |.| the Euclidean norm.
// It is the CRPS when all points lie on one line. O(n^2): about n^2 / 2 norms, fine for n up to a
// few thousand (n = 5000: about 80 ms on one core). For n == 1 it is |x_1 - y|.
double EnergyScore(std::span<const Eigen::Vector2d> ensemble, const Eigen::Vector2d& observed);

// Leave-one-out climatologies of a set of observed values (or 2-D points): entry k is the score
// of values[k] against all the other values, CrpsEnsemble(others, values[k]) and
// EnergyScore(others, points[k]) up to rounding; NaN for fewer than 2 values. The CRPS for all k
// in O(n log n) from sorted values and prefix sums (the pairs without k are all pairs less those
// with k, and those are the same distances as between k and the others); the energy scores in
// O(n^2) (about n^2 / 2 norms), instead of a sort or an O(n^2) score per k.
std::vector<double> LeaveOneOutCrps(std::span<const double> values);
std::vector<double> LeaveOneOutEnergyScores(std::span<const Eigen::Vector2d> points);

// Probability integral transform of the observation within the ensemble (its rank, made
// continuous): PIT = (below + u (equal + 1)) / (n + 1), with below and equal the numbers of
// members < and == observed and u uniform on [0, 1) drawn by the caller. The one u both breaks
// ties at random and spreads the rank over its bin, so the PIT is exactly uniform on [0, 1) when
// the observation and the members are exchangeable (drawn from one distribution), ties or not.
// u == 1 is accepted too (some generators return it); the result then lies in [0, 1].
double Pit(std::span<const double> ensemble, double observed, double u);

// The type-7 quantile (linear interpolation between order statistics; R's and NumPy's default)
// of the ensemble at probability p in [0, 1]: with x_(0) <= ... <= x_(n-1) and h = (n - 1) p,
// x_(floor h) + (h - floor h) (x_(floor h + 1) - x_(floor h)).
double Quantile(std::span<const double> ensemble, double p);

// Everything reported per scalar observation (run-out distance, m; deposit height, m; ...).
// All values but members, pit and inside_90 are in the unit of the observation.
struct ScalarScore {
  int members = 0;  // ensemble size n
  double observed = 0;
  double crps = 0;  // CrpsEnsemble, fair estimator
  double pit = 0;   // Pit with the caller's u, in [0, 1]
  double mean = 0;
  double median = 0;       // type-7 quantile at 0.5 (the usual median)
  double sd = 0;           // sample standard deviation, divisor n - 1; 0 when n == 1
  double q05 = 0;          // 5 % quantile of the ensemble, type 7 (see Quantile)
  double q95 = 0;          // 95 % quantile of the ensemble, type 7
  bool inside_90 = false;  // q05 <= observed <= q95
  double bias = 0;         // mean - observed
};

// Scores one scalar observation against its ensemble; u as for Pit.
ScalarScore ScoreScalar(std::span<const double> ensemble, double observed, double u);

// A histogram of PIT values with Pearson's chi-square test of uniformity.
struct PitHistogram {
  std::vector<int> counts;  // bins of equal width on [0, 1]; bin k holds [k/b, (k+1)/b), 1 the last
  double chi_square = 0;    // sum_k (counts_k - N/b)^2 / (N/b), N = number of PIT values
  int degrees_of_freedom = 0;  // b - 1
  double p_value = 1;          // upper tail of the chi-square distribution; 1 when b == 1
};

// Bins the PIT values (each in [0, 1], at least one) into `bins` >= 1 equal bins and tests them
// for uniformity. The chi-square approximation wants about 5 or more expected per bin (N/b >= 5).
PitHistogram MakePitHistogram(std::span<const double> pits, int bins);

// Skill against a reference forecast: 1 - score / reference_score, for negatively oriented scores
// such as the CRPS (1 perfect, 0 no better than the reference, < 0 worse). NaN when
// reference_score is 0.
double SkillScore(double score, double reference_score);

}  // namespace talus::fieldobs
