#include "calibration/covariance.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "calibration/evaluator.hpp"
#include "calibration/report_text.hpp"
#include "calibration/residual_cost.hpp"

namespace talus::calibration {
namespace {

// Ceres logs a rank-deficient covariance as an error on stderr; here it is an expected outcome,
// reported in Uncertainty. Quiets glog below FATAL while alive (one thread computes it).
class QuietCeresLog {
 public:
  QuietCeresLog() : level_(FLAGS_minloglevel) { FLAGS_minloglevel = google::GLOG_FATAL; }
  ~QuietCeresLog() { FLAGS_minloglevel = level_; }
  QuietCeresLog(const QuietCeresLog&) = delete;
  QuietCeresLog& operator=(const QuietCeresLog&) = delete;

 private:
  int level_;
};

// The parameters at u with nothing estimated yet: every coordinate identified, no standard error.
Uncertainty Unestimated(const Objective& objective, const Eigen::VectorXd& u) {
  const int n = objective.dimension();
  Uncertainty out;
  for (const Coordinate& c : objective.parameters().coordinates()) out.names.push_back(c.name);
  out.u = u;
  out.values = objective.parameters().Values(u);
  out.identified.assign(static_cast<std::size_t>(n), true);
  out.weak.assign(static_cast<std::size_t>(n), false);
  out.standard_error = Eigen::VectorXd::Constant(n, kNaN);
  out.standard_error_unit = Eigen::VectorXd::Constant(n, kNaN);
  out.offset_unit = Eigen::VectorXd::Zero(n);
  out.stationary_values = Eigen::VectorXd::Constant(n, kNaN);
  out.covariance_unit = Eigen::MatrixXd::Zero(n, n);
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.correlation = Eigen::MatrixXd::Constant(n, n, kNaN);
  return out;
}

// (J^T J)^-1 at x into *inverse by ceres::Covariance (dense SVD), the coordinates `constant` held
// (a ceres::SubsetManifold); false when every coordinate is held or J^T J is rank-deficient.
bool InverseOfJtJ(ceres::Problem& problem, std::vector<double>& x, const std::vector<int>& constant,
                  const UncertaintyOptions& options, RowMajor* inverse) {
  const int n = static_cast<int>(x.size());
  if (static_cast<int>(constant.size()) >= n) return false;
  if (!constant.empty()) problem.SetManifold(x.data(), new ceres::SubsetManifold(n, constant));
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.min_reciprocal_condition_number = options.min_reciprocal_condition_number;
  covariance_options.null_space_rank = 0;  // rank-deficient: refuse, and profile instead
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  return covariance.Compute(std::vector<const double*>{x.data()}, &problem) &&
         covariance.GetCovarianceBlock(x.data(), x.data(), inverse->data());
}

// The names of the coordinates `pick` chooses, for the note.
std::string Names(const Uncertainty& out, const std::function<bool(int)>& pick) {
  std::string s;
  for (int j = 0; j < static_cast<int>(out.names.size()); ++j)
    if (pick(j)) s += (s.empty() ? "" : ", ") + out.names[static_cast<std::size_t>(j)];
  return s;
}

// Sandwich: (J^T J)^-1 M (J^T J)^-1, M = sum over runs of (J_g^T r_g)(J_g^T r_g)^T (times
// G / (G - n)) plus the prior's w sum_i J_i^T J_i over its rows, into
// out.covariance_unit, with out.groups the runs with a score gradient. "" when computed, else why
// not.
std::string Sandwich(const Objective& objective, const RowMajor& inverse, Uncertainty& out) {
  const int n = objective.dimension();
  const int m = objective.residual_count();
  const auto& groups = objective.residual_groups();
  int group_count = 0;
  for (int g : groups) group_count = std::max(group_count, g + 1);
  Eigen::MatrixXd gradients = Eigen::MatrixXd::Zero(group_count, n);
  for (int i = 0; i < m; ++i)
    if (groups[static_cast<std::size_t>(i)] >= 0)
      gradients.row(groups[static_cast<std::size_t>(i)]) += out.residuals[i] * out.jacobian.row(i);
  for (int g = 0; g < group_count; ++g) out.groups += gradients.row(g).squaredNorm() > 0 ? 1 : 0;
  // The parameters the runs estimate: identified, moving some run's residuals, and with a
  // profile that is not flat when profiles were measured (one that only its prior holds takes no
  // degree of freedom from the runs).
  int free = 0;
  for (int j = 0; j < n; ++j) {
    bool data = out.profiles.size() != static_cast<std::size_t>(n) ||
                out.profiles[static_cast<std::size_t>(j)].identified;
    bool moves = false;
    for (int i = 0; i < m && !moves; ++i)
      moves = groups[static_cast<std::size_t>(i)] >= 0 && out.jacobian(i, j) != 0;
    free += out.identified[static_cast<std::size_t>(j)] && data && moves ? 1 : 0;
  }
  if (out.groups <= free)
    return "No covariance: " + std::to_string(out.groups) + " runs with a score gradient for " +
           std::to_string(free) + " parameters.";
  const Eigen::MatrixXd bread = inverse;
  const Eigen::MatrixXd meat =
      gradients.transpose() * gradients * (double(out.groups) / double(out.groups - free));
  // The prior's rows as pseudo-observations: a residual sqrt(w) (value - mean) / sd whose mean is
  // uncertain by its sd varies with variance w, so its score gradient J_i^T r_i has variance
  // w J_i^T J_i. A coordinate held by its prior alone then gets the prior's sd.
  Eigen::MatrixXd prior_meat = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < m; ++i)
    if (groups[static_cast<std::size_t>(i)] < 0)
      prior_meat +=
          objective.options().prior_weight * out.jacobian.row(i).transpose() * out.jacobian.row(i);
  out.covariance_unit = bread * (meat + prior_meat) * bread;
  out.computed = true;
  return "";
}

// The Gauss-Newton step at the covariance's step, d = -(J^T J)^-1 f'_h / 2, from the objective's
// central differences at the Jacobian's points (answered from the cache), shortened to the
// stencil (no coordinate beyond h) and kept inside the box,
// into out.offset_unit and out.stationary_values; d d^T is added to out.covariance_unit.
// Coordinates held constant have zero rows in `inverse` and get no step.
void Stationarity(const Objective& objective, const EvaluateFn& evaluate, const RowMajor& inverse,
                  double h, Uncertainty& out) {
  const int n = objective.dimension();
  const std::optional<Evaluation> at = evaluate(out.u);
  if (!at || !at->feasible) return;
  Eigen::VectorXd slope = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j) {
    if (!out.identified[static_cast<std::size_t>(j)]) continue;
    // The Jacobian's own pair (ResidualCost), so its evaluations come from the cache.
    const std::optional<CentralDifference> d = TakeCentralDifference(evaluate, *at, j, h);
    if (!d) return;
    slope[j] = (d->hi.value - d->lo.value) / d->width;
  }
  // The slope was measured over u -+ h: a longer step extrapolates the smoothed model beyond
  // where it was measured (along a valley of correlated parameters, to a corner of the box), so
  // the step is shortened to the stencil, its direction kept.
  Eigen::VectorXd step = -0.5 * Eigen::MatrixXd(inverse) * slope;
  const double longest = step.cwiseAbs().maxCoeff();
  out.offset_limited = longest > h;
  if (out.offset_limited) step *= h / longest;
  const Eigen::VectorXd target = (out.u + step).cwiseMax(0.0).cwiseMin(1.0);
  out.stationary_located = true;
  out.offset_unit = target - out.u;
  out.stationary_values = objective.parameters().Values(target);
  out.covariance_unit += out.offset_unit * out.offset_unit.transpose();
}

// The covariance in physical units (through the transforms' Jacobian), the standard errors, which
// are weak, and the correlations of the identified coordinates.
void InPhysicalUnits(const Objective& objective, const UncertaintyOptions& options,
                     Uncertainty& out) {
  const int n = objective.dimension();
  const auto& coordinates = objective.parameters().coordinates();
  Eigen::VectorXd d(n);  // d value / d u
  for (int j = 0; j < n; ++j) {
    const Coordinate& c = coordinates[static_cast<std::size_t>(j)];
    d[j] = c.log ? out.values[j] * (std::log(c.upper) - std::log(c.lower)) : c.upper - c.lower;
  }
  out.covariance = d.asDiagonal() * out.covariance_unit * d.asDiagonal();
  for (int j = 0; j < n; ++j) {
    if (!out.identified[static_cast<std::size_t>(j)]) continue;
    out.standard_error_unit[j] = std::sqrt(std::max(0.0, out.covariance_unit(j, j)));
    out.standard_error[j] = std::sqrt(std::max(0.0, out.covariance(j, j)));
    out.weak[static_cast<std::size_t>(j)] = out.standard_error_unit[j] > options.weak_fraction;
    for (int k = 0; k < n; ++k)
      if (out.identified[static_cast<std::size_t>(k)])
        out.correlation(j, k) = out.covariance_unit(j, k) /
                                std::sqrt(out.covariance_unit(j, j) * out.covariance_unit(k, k));
  }
}

// `note` (the unidentified parameters) with the weakly constrained ones and those at a bound.
std::string ConstraintNote(std::string note, const Eigen::VectorXd& u,
                           const UncertaintyOptions& options, const Uncertainty& out) {
  const std::string weak =
      Names(out, [&](int j) { return bool(out.weak[static_cast<std::size_t>(j)]); });
  if (!weak.empty()) {
    char b[64];
    std::snprintf(b, sizeof b, "%.2g", options.weak_fraction);
    note += "weakly constrained (standard error above " + std::string(b) +
            " of the range): " + weak + ". ";
  }
  // At a bound: within kAtBoundOfRange, as CalibrationWarnings and the ground table say it.
  // Near one: within the covariance's step, where its differences are cut short on that side;
  // with steps of up to 0.25 that is no statement that the optimum lies beyond the bound.
  const auto at = [&](int j) { return AtLowerBound(u[j]) || AtUpperBound(u[j]); };
  const std::string at_bound = Names(
      out, [&](int j) { return out.identified[static_cast<std::size_t>(j)] && at(j); });
  const std::string near_bound = Names(out, [&](int j) {
    return out.identified[static_cast<std::size_t>(j)] && !at(j) &&
           std::min(u[j], 1 - u[j]) <= options.fd_step;
  });
  if (!at_bound.empty())
    note +=
        "at a bound (the optimum may lie beyond it; the interval is not reliable): " + at_bound +
        ". ";
  if (!near_bound.empty())
    note += "within the finite-difference step of a bound (its differences are cut short there): " +
            near_bound + ". ";
  if (note.empty()) note = "every parameter is constrained by the observations.";
  while (!note.empty() && note.back() == ' ') note.pop_back();
  return note;
}

}  // namespace

bool UncertaintyOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (!(fd_step > 0 && fd_step <= 0.25))
    msg << "fd_step = " << fd_step << " must be in (0, 0.25] (a fraction of the range)";
  else if (!(min_reciprocal_condition_number > 0 && min_reciprocal_condition_number < 1))
    msg << "min_reciprocal_condition_number = " << min_reciprocal_condition_number
        << " must be in (0, 1)";
  else if (!(weak_fraction > 0))
    msg << "weak_fraction = " << weak_fraction << " must be > 0";
  else if (!(noise >= 0))
    msg << "noise = " << noise << " must be >= 0";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

Uncertainty EstimateUncertainty(const Objective& objective, const Eigen::VectorXd& u,
                                const UncertaintyOptions& options,
                                const std::vector<Evaluation>& known) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("EstimateUncertainty: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  const int n = objective.dimension();
  const int m = objective.residual_count();
  Uncertainty out = Unestimated(objective, u);
  out.fd_step = options.fd_step;

  // Evaluations through the Evaluator's cache: the known ones (a calibration's history), else the
  // objective's, with no budget; an exception is kept and rethrown.
  OptimizerOptions unlimited;
  unlimited.max_evaluations = std::numeric_limits<int>::max();
  OptimizerSummary record;
  record.history = known;
  record.history_start.assign(known.size(), 0);
  Evaluator evaluator(objective, unlimited, record);
  const EvaluateFn evaluate = [&evaluator](const Eigen::VectorXd& v) {
    return evaluator.TryEvaluate(v);
  };
  int profile_evaluations = 0;
  const auto finish = [&](const std::string& note) {
    evaluator.Rethrow();
    out.evaluations = record.evaluations() - static_cast<int>(known.size()) + profile_evaluations;
    out.note = note;
    out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };

  std::vector<double> x(u.data(), u.data() + n);
  ceres::Problem problem;
  problem.AddResidualBlock(new ResidualCost(evaluate, n, m, options.fd_step), nullptr, x.data());
  double cost = 0;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &residuals, nullptr, &crs))
    return finish(
        "no covariance: the residuals or their differences could not be evaluated at "
        "the optimum (infeasible neighbours)");
  out.residuals = Eigen::Map<const Eigen::VectorXd>(residuals.data(), m);
  out.jacobian = Eigen::MatrixXd::Zero(m, n);
  for (int i = 0; i < crs.num_rows; ++i)
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k)
      out.jacobian(i, crs.cols[k]) = crs.values[k];

  const QuietCeresLog quiet;
  RowMajor inverse = RowMajor::Zero(n, n);  // (J^T J)^-1 of the identified coordinates
  // A coordinate with a prior term is constrained by its prior rows even where the observations
  // leave it free (a flat profile): it stays in the covariance, with its prior's uncertainty.
  const std::vector<int>& with_prior = objective.prior_coordinates();
  const auto has_prior = [&](int j) {
    return std::find(with_prior.begin(), with_prior.end(), j) != with_prior.end();
  };
  std::vector<int> flat;  // coordinates whose given profile is flat and that no prior holds
  if (static_cast<int>(options.profiles.size()) == n) {
    out.profiles = options.profiles;
    for (int j = 0; j < n; ++j)
      if (!options.profiles[static_cast<std::size_t>(j)].identified && !has_prior(j)) {
        out.identified[static_cast<std::size_t>(j)] = false;
        flat.push_back(j);
      }
  }
  bool ok = InverseOfJtJ(problem, x, flat, options, &inverse);
  if (!ok && flat.empty()) {
    // Rank-deficient: the profiles decide which coordinates the observations see; the others are
    // held constant for the covariance of the rest.
    evaluator.Rethrow();
    out.rank_deficient = true;
    const Evaluation at = *evaluate(u);
    out.profiles = ProfileParameters(objective, u, at.value, options.noise, options.profile);
    profile_evaluations = n * std::max(2, options.profile.points);
    std::vector<int> constant;
    for (int j = 0; j < n; ++j) {
      out.identified[static_cast<std::size_t>(j)] =
          out.profiles[static_cast<std::size_t>(j)].identified || has_prior(j);
      if (!out.identified[static_cast<std::size_t>(j)]) constant.push_back(j);
    }
    ok = InverseOfJtJ(problem, x, constant, options, &inverse);
  }

  const std::string unidentified =
      Names(out, [&](int j) { return !out.identified[static_cast<std::size_t>(j)]; });
  std::string note;
  if (!unidentified.empty())
    note += "not constrained by the observations (flat profile): " + unidentified + ". ";
  const auto none = std::count(out.identified.begin(), out.identified.end(), false);
  if (!ok && none == n) return finish(note + "No covariance: no parameter is identified.");
  if (!ok)
    return finish(note + "No covariance: J^T J is rank-deficient" +
                  (none > 0 ? " even without the unconstrained parameters." : "."));
  if (const std::string no = Sandwich(objective, inverse, out); !no.empty())
    return finish(note + no);
  if (options.gradient_resolved) {
    Stationarity(objective, evaluate, inverse, options.fd_step, out);
    evaluator.Rethrow();
  }
  InPhysicalUnits(objective, options, out);
  return finish(ConstraintNote(note, u, options, out));
}

std::string Uncertainty::Report() const {
  char step[32];
  std::snprintf(step, sizeof step, "%.3g", fd_step);
  std::string out = "Uncertainty (sandwich covariance from Ceres, " + std::to_string(groups) +
                    " runs, step " + step + ", " + std::to_string(evaluations) + " evaluations):\n";
  char line[256];
  std::snprintf(line, sizeof line, "  %-28s %14s %14s %10s  %s\n", "parameter", "value",
                "std. error", "(of range)", "");
  out += line;
  for (std::size_t j = 0; j < names.size(); ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    std::snprintf(line, sizeof line, "  %-28s %14s %14s %10s  %s\n", names[j].c_str(),
                  Num(values[k], "%.6g").c_str(), Num(standard_error[k], "%.4g").c_str(),
                  Num(standard_error_unit[k], "%.3f").c_str(),
                  !identified[j] ? "UNIDENTIFIED"
                  : weak[j]      ? "weak"
                                 : "");
    out += line;
  }
  if (computed && names.size() > 1) {
    out += "  correlations:\n";
    for (std::size_t j = 0; j < names.size(); ++j) {
      out += "    ";
      for (std::size_t k = 0; k < names.size(); ++k)
        out +=
            Num(correlation(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(k)), "%6.2f") +
            " ";
      out += "\n";
    }
  }
  if (computed && !stationary_located)
    out +=
        "  the smoothed objective's stationary point is not located: the differences at this "
        "step are noise-dominated\n";
  if (stationary_located) {
    out += std::string(
               "  the smoothed objective's stationary point, one Gauss-Newton step at the "
               "step above") +
           (offset_limited ? ", shortened to it" : "") +
           " (its distance is in the standard errors):\n";
    for (std::size_t j = 0; j < names.size(); ++j) {
      const auto k = static_cast<Eigen::Index>(j);
      if (!identified[j]) continue;
      std::snprintf(line, sizeof line, "    %-26s %14s  (%+.3f of range)\n", names[j].c_str(),
                    Num(stationary_values[k], "%.6g").c_str(), offset_unit[k]);
      out += line;
    }
  }
  return out + "  " + note + "\n";
}

}  // namespace talus::calibration
