#include "calibration/least_squares.hpp"

#include <ceres/ceres.h>

#include <Eigen/QR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "calibration/designs.hpp"
#include "calibration/evaluator.hpp"
#include "calibration/report_text.hpp"

namespace talus::calibration {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
constexpr double kInf = std::numeric_limits<double>::infinity();
using EvaluateFn = std::function<std::optional<Evaluation>(const Eigen::VectorXd&)>;

// The pair u -+ h e_j of a central difference, moved inside [0, 1] at a bound.
std::pair<Eigen::VectorXd, Eigen::VectorXd> CentralPair(const Eigen::VectorXd& u, int j, double h) {
  Eigen::VectorXd lo = u, hi = u;
  lo[j] = std::max(0.0, u[j] - h);
  hi[j] = std::min(1.0, u[j] + h);
  return {lo, hi};
}

// The residual vector with central differences of absolute step h in unit coordinates. A point
// that cannot be evaluated (infeasible, budget spent, interrupted) makes Ceres reject the step.
class ResidualCost final : public ceres::CostFunction {
 public:
  ResidualCost(EvaluateFn evaluate, int n, int m, double h)
      : evaluate_(std::move(evaluate)), n_(n), m_(m), h_(h) {
    set_num_residuals(m);
    mutable_parameter_block_sizes()->push_back(n);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(parameters[0], n_);
    const std::optional<Evaluation> e = evaluate_(u);
    if (!e || !e->feasible) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, m_) = e->residuals;
    if (!jacobians || !jacobians[0]) return true;
    Eigen::Map<RowMajor> jacobian(jacobians[0], m_, n_);
    for (int j = 0; j < n_; ++j) {
      // u itself where a side is infeasible.
      auto [lo, hi] = CentralPair(u, j, h_);
      std::optional<Evaluation> a = lo[j] == u[j] ? e : evaluate_(lo);
      std::optional<Evaluation> b = hi[j] == u[j] ? e : evaluate_(hi);
      if (!a && !b) return false;
      if (a && !a->feasible) a = e, lo = u;
      if (b && !b->feasible) b = e, hi = u;
      if (!a || !b || hi[j] == lo[j]) return false;
      jacobian.col(j) = (b->residuals - a->residuals) / (hi[j] - lo[j]);
    }
    return true;
  }

 private:
  EvaluateFn evaluate_;
  int n_, m_;
  double h_;
};

// (J^T J)_jj of the central difference of step h at u, and the stencil's width w (2h inside the
// box; u itself stands in for an infeasible side). `at` is the evaluation at u.
struct Difference {
  double width = 0, jtj = 0;
};
Difference MeasureDifference(const Objective& objective, const Evaluation& at, int j, double h,
                             int* evaluations) {
  auto [lo, hi] = CentralPair(at.u, j, h);
  const auto side = [&](Eigen::VectorXd& v) {
    if (v[j] == at.u[j]) return at.residuals;
    ++*evaluations;
    const Evaluation e = objective.Evaluate(v);
    if (e.feasible) return e.residuals;
    v = at.u;
    return at.residuals;
  };
  const Eigen::VectorXd a = side(lo), b = side(hi);
  Difference d;
  d.width = hi[j] - lo[j];
  if (d.width > 0) d.jtj = ((b - a) / d.width).squaredNorm();
  return d;
}

// Stops Ceres once the evaluator has stopped (budget, time, an exception to rethrow).
class BudgetCallback final : public ceres::IterationCallback {
 public:
  explicit BudgetCallback(const Evaluator& evaluate) : evaluate_(evaluate) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return evaluate_.stopped() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const Evaluator& evaluate_;
};

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

// The fit is the best point where a start's Levenberg-Marquardt ended (its accepted iterates only
// decrease the cost), not the best evaluation: the difference points around an iterate were
// evaluated to estimate a derivative, and on a rough objective the lowest of them is the lowest
// draw of its noise, not a better fit (on the Tyrol DEM one such point, a step below where Ceres
// stopped, was reported as the fit).
void KeepBestIterate(OptimizerSummary& summary) {
  std::optional<Evaluation> best;
  for (const StartRecord& start : summary.starts)
    for (const Evaluation& e : summary.history)
      if (e.u == start.best_u && e.feasible && (!best || e.value < best->value)) best = e;
  if (best) summary.best = *best;
}

// Where Levenberg-Marquardt starts when the Jacobian is noise-dominated (StepChoice): the
// minimiser of the residuals' linear model r(u) ~ a + B (u - c), clamped to the box coordinate by
// coordinate (the box's minimiser of the model for one parameter, a start near it for more), with
// the model fitted by least squares
// to a design -- `start` and 4 (n + 1) - 1 points of the optimiser's start design --, a response
// surface (Box & Wilson 1951) in Gauss-Newton form. A difference quotient over one stencil sees
// the noise of two points; the regression's slope averages it over the design and the box, so the
// model sees a trend that no local difference resolves. Ceres then goes on from there. The design's
// evaluations are in the history (and the budget); `start` when too few are feasible.
Eigen::VectorXd ResponseSurfaceStart(const Objective& objective, const OptimizerOptions& options,
                                     const Eigen::VectorXd& start, Evaluator& evaluate) {
  const int n = objective.dimension();
  OptimizerOptions design = options;
  design.start = start;
  design.starts = 4 * (n + 1);
  if (n > kMaxSobolDimension) design.start_design = "lhs";
  std::vector<Evaluation> points;
  for (const Eigen::VectorXd& u : StartPoints(objective, design)) {
    const std::optional<Evaluation> e = evaluate.TryEvaluate(u);
    if (e && e->feasible) points.push_back(*e);
  }
  const auto k = static_cast<Eigen::Index>(points.size());
  if (k < n + 2) return start;
  Eigen::VectorXd centre = Eigen::VectorXd::Zero(n);
  for (const Evaluation& e : points) centre += e.u / double(k);
  Eigen::MatrixXd x(k, n + 1), y(k, objective.residual_count());
  for (Eigen::Index i = 0; i < k; ++i) {
    const Evaluation& e = points[static_cast<std::size_t>(i)];
    x(i, 0) = 1;
    x.row(i).tail(n) = (e.u - centre).transpose();
    y.row(i) = e.residuals.transpose();
  }
  const Eigen::MatrixXd model = x.colPivHouseholderQr().solve(y);  // (n + 1) x m
  const Eigen::VectorXd a = model.row(0).transpose();
  const Eigen::MatrixXd b = model.bottomRows(n).transpose();
  const Eigen::VectorXd step = b.colPivHouseholderQr().solve(-a);
  return (centre + step).cwiseMax(0.0).cwiseMin(1.0);
}

}  // namespace

OptimizerSummary OptimizeLeastSquares(const Objective& objective, const OptimizerOptions& options) {
  const int n = objective.dimension();
  const int m = objective.residual_count();
  const std::vector<Eigen::VectorXd> starts = StartPoints(objective, options);
  OptimizerSummary summary;
  summary.algorithm = options.algorithm;
  for (const Coordinate& c : objective.parameters().coordinates()) summary.names.push_back(c.name);
  Evaluator evaluate(objective, options, summary);
  evaluate(starts.front());

  summary.fd_step = options.fd_step;
  Eigen::VectorXd first = starts.front();
  if (!(summary.fd_step > 0)) {
    const StepChoice step = ChooseFiniteDifferenceStep(objective, starts.front());
    summary.fd_step = step.step;
    if (step.noise_dominated) {
      summary.fd_shrink = step.shrink();
      first = ResponseSurfaceStart(objective, options, starts.front(), evaluate);
    }
  }

  ceres::TerminationType last = ceres::CONVERGENCE;
  std::string last_message;
  for (std::size_t s = 0; s < starts.size() && !evaluate.stopped(); ++s) {
    evaluate.set_start(static_cast<int>(s));
    const int before = summary.evaluations();
    const Eigen::VectorXd& x0 = s == 0 ? first : starts[s];
    std::vector<double> x(x0.data(), x0.data() + n);
    ceres::Problem problem;
    problem.AddResidualBlock(
        new ResidualCost([&](const Eigen::VectorXd& u) { return evaluate.TryEvaluate(u); }, n, m,
                         summary.fd_step),
        nullptr, x.data());
    for (int j = 0; j < n; ++j) {
      problem.SetParameterLowerBound(x.data(), j, 0.0);
      problem.SetParameterUpperBound(x.data(), j, 1.0);
    }
    ceres::Solver::Options solver;
    solver.minimizer_type = ceres::TRUST_REGION;
    solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    solver.linear_solver_type = ceres::DENSE_QR;
    solver.num_threads = 1;             // the evaluations use the threads
    solver.max_num_iterations = 10000;  // the evaluation budget stops it
    solver.function_tolerance = std::max(options.ftol_rel, 1e-16);
    // Ceres' test is relative: |step| <= (|u| + tol) tol, with |u| <= sqrt(n) in unit coordinates.
    solver.parameter_tolerance = std::max(options.xtol_abs, 1e-16);
    solver.logging_type = ceres::SILENT;
    BudgetCallback callback(evaluate);
    solver.callbacks.push_back(&callback);
    ceres::Solver::Summary result;
    ceres::Solve(solver, &problem, &result);
    evaluate.Rethrow();
    last = result.termination_type;
    last_message = result.message;

    StartRecord record;
    record.u0 = x0;
    record.best_u = Eigen::Map<const Eigen::VectorXd>(x.data(), n);
    record.best_value = 2 * result.final_cost;  // Ceres' cost is half the sum of squares
    record.evaluations = summary.evaluations() - before;
    record.result = std::string(ceres::TerminationTypeToString(result.termination_type)) + ": " +
                    result.message;
    summary.starts.push_back(record);
  }

  KeepBestIterate(summary);
  evaluate.Finish(evaluate.out_of_evaluations(),
                  last == ceres::CONVERGENCE || last == ceres::USER_SUCCESS, last_message,
                  "Ceres stopped: " + last_message);
  return summary;
}

bool StepChoiceOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (!(small > 0 && small < large && large <= 0.5))
    msg << "steps small = " << small << " and large = " << large
        << " must satisfy 0 < small < large <= 0.5";
  else if (!(noise_share > 0))
    msg << "noise_share = " << noise_share << " must be > 0";
  else if (!(max_step >= small && max_step <= 0.5))
    msg << "max_step = " << max_step << " must be in [small, 0.5]";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

StepChoice ChooseFiniteDifferenceStep(const Objective& objective, const Eigen::VectorXd& u,
                                      const StepChoiceOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("ChooseFiniteDifferenceStep: " + why);
  StepChoice out;
  const Evaluation at = objective.Evaluate(u);
  out.evaluations = 1;
  out.step = options.small;
  if (!at.feasible) {  // nothing to measure: Ceres cannot start here either
    out.step = options.large;
    return out;
  }
  for (int j = 0; j < objective.dimension(); ++j) {
    const Difference d1 = MeasureDifference(objective, at, j, options.small, &out.evaluations);
    const Difference d2 = MeasureDifference(objective, at, j, options.large, &out.evaluations);
    if (d1.width == 0 || d2.width == 0) {  // a stencil with no feasible side: nothing measured
      out.noise.push_back(0);
      out.signal.push_back(0);
      out.step = std::max(out.step, options.large);
      continue;
    }
    // D(w) = S + N / w^2 through the two points.
    double noise = 0, signal = d2.jtj;
    const double x1 = d1.width > 0 ? 1 / (d1.width * d1.width) : 0;
    const double x2 = d2.width > 0 ? 1 / (d2.width * d2.width) : 0;
    if (x1 > x2) {
      noise = std::max(0.0, (d1.jtj - d2.jtj) / (x1 - x2));
      signal = d2.jtj - noise * x2;
    }
    out.noise.push_back(noise);
    out.signal.push_back(signal);
    if (noise == 0) continue;  // the smaller step sees no noise: it will do
    const double h = signal > 0 ? std::sqrt(noise / (options.noise_share * signal)) / 2 : kInf;
    if (h > options.max_step) out.noise_dominated = true;
    out.step = std::max(out.step, std::min(h, options.max_step));
  }
  return out;
}

double StepChoice::shrink() const {
  double out = 1;
  const double w = 2 * step;
  for (std::size_t j = 0; j < signal.size(); ++j) {
    if (noise[j] == 0) continue;  // no noise seen (or nothing measured): no shortening
    out = std::min(out, signal[j] > 0 ? 1 / (1 + noise[j] / (signal[j] * w * w)) : 0.0);
  }
  return out;
}

std::string StepChoice::Report() const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line,
                "Finite-difference step %.3g (%d evaluations); Gauss-Newton steps shortened to "
                "%.2g%s\n",
                step, evaluations, shrink(),
                noise_dominated ? " (noise-dominated at every step within the box)" : "");
  out += line;
  for (std::size_t j = 0; j < signal.size(); ++j) {
    std::snprintf(line, sizeof line, "  coordinate %zu: J^T J = %.4g + %.4g / w^2\n", j, signal[j],
                  noise[j]);
    out += line;
  }
  return out;
}

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
  const auto& coordinates = objective.parameters().coordinates();
  Uncertainty out;
  for (const Coordinate& c : coordinates) out.names.push_back(c.name);
  out.u = u;
  out.values = objective.parameters().Values(u);
  out.identified.assign(static_cast<std::size_t>(n), true);
  out.weak.assign(static_cast<std::size_t>(n), false);
  out.standard_error = Eigen::VectorXd::Constant(n, kNaN);
  out.standard_error_unit = Eigen::VectorXd::Constant(n, kNaN);
  out.covariance_unit = Eigen::MatrixXd::Zero(n, n);
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.correlation = Eigen::MatrixXd::Constant(n, n, kNaN);

  // Evaluations: the known ones, else the objective's; an exception is kept and rethrown.
  std::vector<Evaluation> cache = known;
  std::exception_ptr error;
  const EvaluateFn evaluate = [&](const Eigen::VectorXd& v) -> std::optional<Evaluation> {
    for (const Evaluation& e : cache)
      if (e.u == v) return e;
    if (error) return std::nullopt;
    try {
      cache.push_back(objective.Evaluate(v));
      ++out.evaluations;
      return cache.back();
    } catch (...) {
      error = std::current_exception();
      return std::nullopt;
    }
  };
  const auto finish = [&](const std::string& note) {
    if (error) std::rethrow_exception(error);
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

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.min_reciprocal_condition_number = options.min_reciprocal_condition_number;
  covariance_options.null_space_rank = 0;  // rank-deficient: refuse, and profile instead
  covariance_options.num_threads = 1;
  const QuietCeresLog quiet;
  RowMajor inverse = RowMajor::Zero(n, n);  // (J^T J)^-1 of the identified coordinates
  bool ok = false;
  std::vector<int> flat;  // coordinates whose given profile is flat
  if (static_cast<int>(options.profiles.size()) == n) {
    out.profiles = options.profiles;
    for (int j = 0; j < n; ++j)
      if (!options.profiles[static_cast<std::size_t>(j)].identified) {
        out.identified[static_cast<std::size_t>(j)] = false;
        flat.push_back(j);
      }
    if (!flat.empty() && static_cast<int>(flat.size()) < n)
      problem.SetManifold(x.data(), new ceres::SubsetManifold(n, flat));
  }
  if (static_cast<int>(flat.size()) < n) {
    ceres::Covariance covariance(covariance_options);
    ok = covariance.Compute(std::vector<const double*>{x.data()}, &problem) &&
         covariance.GetCovarianceBlock(x.data(), x.data(), inverse.data());
  }
  if (!ok && flat.empty()) {
    // Rank-deficient: the profiles decide which coordinates the observations see; the others are
    // held constant for the covariance of the rest.
    if (error) return finish("");
    out.rank_deficient = true;
    const Evaluation at = *evaluate(u);
    out.profiles = ProfileParameters(objective, u, at.value, options.noise, options.profile);
    out.evaluations += n * std::max(2, options.profile.points);
    std::vector<int> constant;
    for (int j = 0; j < n; ++j) {
      out.identified[static_cast<std::size_t>(j)] =
          out.profiles[static_cast<std::size_t>(j)].identified;
      if (!out.identified[static_cast<std::size_t>(j)]) constant.push_back(j);
    }
    if (static_cast<int>(constant.size()) < n) {
      if (!constant.empty()) problem.SetManifold(x.data(), new ceres::SubsetManifold(n, constant));
      ceres::Covariance covariance(covariance_options);
      ok = covariance.Compute(std::vector<const double*>{x.data()}, &problem) &&
           covariance.GetCovarianceBlock(x.data(), x.data(), inverse.data());
    }
  }

  // Names for the note.
  const auto list = [&](const std::function<bool(int)>& pick) {
    std::string s;
    for (int j = 0; j < n; ++j)
      if (pick(j)) s += (s.empty() ? "" : ", ") + out.names[static_cast<std::size_t>(j)];
    return s;
  };
  const std::string unidentified =
      list([&](int j) { return !out.identified[static_cast<std::size_t>(j)]; });
  std::string note;
  if (!unidentified.empty())
    note += "not constrained by the observations (flat profile): " + unidentified + ". ";
  const auto none = std::count(out.identified.begin(), out.identified.end(), false);
  if (!ok && none == n) return finish(note + "No covariance: no parameter is identified.");
  if (!ok)
    return finish(note + "No covariance: J^T J is rank-deficient" +
                  (none > 0 ? " even without the unconstrained parameters." : "."));

  // Sandwich: (J^T J)^-1 M (J^T J)^-1, M = sum over runs of (J_g^T r_g)(J_g^T r_g)^T.
  const auto& groups = objective.residual_groups();
  int group_count = 0;
  for (int g : groups) group_count = std::max(group_count, g + 1);
  Eigen::MatrixXd gradients = Eigen::MatrixXd::Zero(group_count, n);
  for (int i = 0; i < m; ++i)
    if (groups[static_cast<std::size_t>(i)] >= 0)
      gradients.row(groups[static_cast<std::size_t>(i)]) += out.residuals[i] * out.jacobian.row(i);
  for (int g = 0; g < group_count; ++g) out.groups += gradients.row(g).squaredNorm() > 0 ? 1 : 0;
  const int free =
      n - static_cast<int>(std::count(out.identified.begin(), out.identified.end(), false));
  if (out.groups <= free)
    return finish(note + "No covariance: " + std::to_string(out.groups) +
                  " runs with a score gradient for " + std::to_string(free) + " parameters.");
  const Eigen::MatrixXd bread = inverse;
  const Eigen::MatrixXd meat = gradients.transpose() * gradients;
  out.covariance_unit = bread * meat * bread * (double(out.groups) / double(out.groups - free));
  out.computed = true;

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
  const std::string weak = list([&](int j) { return bool(out.weak[static_cast<std::size_t>(j)]); });
  if (!weak.empty()) {
    char b[64];
    std::snprintf(b, sizeof b, "%.2g", options.weak_fraction);
    note += "weakly constrained (standard error above " + std::string(b) +
            " of the range): " + weak + ". ";
  }
  const std::string at_bound = list([&](int j) {
    return out.identified[static_cast<std::size_t>(j)] &&
           (u[j] <= options.fd_step || u[j] >= 1 - options.fd_step);
  });
  if (!at_bound.empty())
    note +=
        "at a bound (the optimum may lie beyond it; the interval is not reliable): " + at_bound +
        ". ";
  if (note.empty()) note = "every parameter is constrained by the observations.";
  while (!note.empty() && note.back() == ' ') note.pop_back();
  return finish(note);
}

std::string Uncertainty::Report() const {
  std::string out = "Uncertainty (sandwich covariance from Ceres, " + std::to_string(groups) +
                    " runs, " + std::to_string(evaluations) + " evaluations):\n";
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
  return out + "  " + note + "\n";
}

}  // namespace talus::calibration
