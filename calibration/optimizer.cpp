#include "calibration/optimizer.hpp"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>

#include "calibration/designs.hpp"
#include "calibration/evaluator.hpp"
#include "calibration/least_squares.hpp"
#include "calibration/report_text.hpp"

namespace talus::calibration {
namespace {

nlopt_algorithm AlgorithmOf(const std::string& name) {
  if (name == "bobyqa") return NLOPT_LN_BOBYQA;
  if (name == "sbplx") return NLOPT_LN_SBPLX;
  if (name == "crs2_lm") return NLOPT_GN_CRS2_LM;
  if (name == "direct_l") return NLOPT_GN_DIRECT_L;
  return NLOPT_GN_ISRES;
}

// The state the NLopt callback works on.
struct Run {
  Evaluator& evaluate;
  nlopt_opt opt = nullptr;
};

double Callback(unsigned n, const double* x, double* /*grad*/, void* data) {
  Run& run = *static_cast<Run*>(data);
  const std::optional<Evaluation> e =
      run.evaluate.TryEvaluate(Eigen::Map<const Eigen::VectorXd>(x, n));
  if (!e || run.evaluate.stopped()) nlopt_force_stop(run.opt);
  return e ? e->value : HUGE_VAL;
}

}  // namespace

const std::vector<std::string>& AlgorithmNames() {
  static const std::vector<std::string> names = {"bobyqa",   "sbplx", "crs2_lm",
                                                 "direct_l", "isres", "ceres"};
  return names;
}

bool IsLocalAlgorithm(const std::string& name) {
  return name == "bobyqa" || name == "sbplx" || name == "ceres";
}

const char* ToString(Termination t) {
  switch (t) {
    case Termination::kConvergence:
      return "convergence";
    case Termination::kMaxEvaluations:
      return "max_evaluations";
    case Termination::kMaxTime:
      return "max_time";
    case Termination::kFailure:
      break;
  }
  return "failure";
}

bool OptimizerOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  const auto& names = AlgorithmNames();
  if (std::find(names.begin(), names.end(), algorithm) == names.end())
    msg << "algorithm = '" << algorithm
        << "' is not one of bobyqa, sbplx, crs2_lm, direct_l, isres, ceres";
  else if (max_evaluations < 1)
    msg << "max_evaluations = " << max_evaluations << " must be >= 1";
  else if (!(max_time_s >= 0) || !std::isfinite(max_time_s))
    msg << "max_time_s = " << max_time_s << " must be >= 0 (0: no limit)";
  else if (!(ftol_rel >= 0) || !(ftol_abs >= 0) || !(xtol_abs >= 0))
    msg << "tolerances must be >= 0 (ftol_rel = " << ftol_rel << ", ftol_abs = " << ftol_abs
        << ", xtol_abs = " << xtol_abs << ")";
  else if (!(initial_step > 0 && initial_step <= 1))
    msg << "initial_step = " << initial_step << " must be in (0, 1] (a fraction of the range)";
  else if (population < 0)
    msg << "population = " << population << " must be >= 0 (0: NLopt's default)";
  else if (starts < 1 || starts > max_evaluations)
    msg << "starts = " << starts << " must be in 1 .. max_evaluations = " << max_evaluations;
  else if (start_design != "sobol" && start_design != "lhs")
    msg << "start_design = '" << start_design << "' must be \"sobol\" or \"lhs\"";
  else if (!(fd_step >= 0 && fd_step <= 0.25))
    msg << "fd_step = " << fd_step << " must be in [0, 0.25] (0: measured)";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

std::vector<Eigen::VectorXd> StartPoints(const Objective& objective,
                                         const OptimizerOptions& options) {
  const int n = objective.dimension();
  if (options.start_design == "sobol" && options.starts > 1 && n > kMaxSobolDimension)
    throw std::invalid_argument("Optimize: Sobol starts for more than 16 parameters; use lhs");
  Eigen::VectorXd x0 = options.start ? *options.start : objective.StartPoint();
  if (x0.size() != n) throw std::invalid_argument("Optimize: start has the wrong dimension");
  std::vector<Eigen::VectorXd> starts = {x0.cwiseMax(0.0).cwiseMin(1.0)};
  if (options.starts > 1) {
    const Eigen::MatrixXd design = options.start_design == "sobol"
                                       ? Sobol(options.starts - 1, n, options.seed)
                                       : LatinHypercube(options.starts - 1, n, options.seed);
    for (int k = 0; k < design.rows(); ++k) starts.push_back(design.row(k).transpose());
  }
  return starts;
}

OptimizerSummary Optimize(const Objective& objective, const OptimizerOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("Optimize: " + why);
  if (options.algorithm == "ceres") return OptimizeLeastSquares(objective, options);
  const int n = objective.dimension();
  const std::vector<Eigen::VectorXd> starts = StartPoints(objective, options);

  OptimizerSummary summary;
  summary.algorithm = options.algorithm;
  for (const Coordinate& c : objective.parameters().coordinates()) summary.names.push_back(c.name);
  Evaluator evaluate(objective, options, summary);
  Run run{evaluate, nullptr};
  // The initial point's evaluation is the first of the history (the optimiser reuses it).
  evaluate(starts.front());

  const std::vector<double> lower(static_cast<std::size_t>(n), 0.0);
  const std::vector<double> upper(static_cast<std::size_t>(n), 1.0);
  const std::vector<double> step(static_cast<std::size_t>(n), options.initial_step);
  const std::vector<double> xtol(static_cast<std::size_t>(n), options.xtol_abs);
  nlopt_result last = NLOPT_SUCCESS;
  for (std::size_t s = 0; s < starts.size(); ++s) {
    const int left = options.max_evaluations - summary.evaluations();
    const double elapsed = evaluate.elapsed_s();
    if (left <= 0 || evaluate.out_of_time() ||
        (options.max_time_s > 0 && elapsed >= options.max_time_s))
      break;
    evaluate.set_start(static_cast<int>(s));
    run.opt = nlopt_create(AlgorithmOf(options.algorithm), static_cast<unsigned>(n));
    if (!run.opt) throw std::runtime_error("Optimize: NLopt could not create its optimiser");
    nlopt_set_min_objective(run.opt, Callback, &run);
    nlopt_set_lower_bounds(run.opt, lower.data());
    nlopt_set_upper_bounds(run.opt, upper.data());
    // This start's share of the evaluations left (its first point may be answered by the cache).
    const int share = std::max(1, left / static_cast<int>(starts.size() - s));
    nlopt_set_maxeval(run.opt, share + (s == 0 ? 1 : 0));
    // Time is watched by the evaluator (after each evaluation), not by NLopt's clock, so that
    // the path does not depend on when NLopt looks at it.
    nlopt_set_ftol_rel(run.opt, options.ftol_rel);
    nlopt_set_ftol_abs(run.opt, options.ftol_abs);
    nlopt_set_xtol_abs(run.opt, xtol.data());
    if (IsLocalAlgorithm(options.algorithm)) nlopt_set_initial_step(run.opt, step.data());
    if (options.population > 0)
      nlopt_set_population(run.opt, static_cast<unsigned>(options.population));
    nlopt_srand(static_cast<unsigned long>(options.seed + s));  // CRS2-LM, ISRES

    std::vector<double> x(starts[s].data(), starts[s].data() + n);
    double f = 0;
    const int before = summary.evaluations();
    last = nlopt_optimize(run.opt, x.data(), &f);
    nlopt_destroy(run.opt);
    run.opt = nullptr;
    evaluate.Rethrow();

    StartRecord record;
    record.u0 = starts[s];
    record.best_u = Eigen::Map<const Eigen::VectorXd>(x.data(), n);
    record.best_value = f;
    record.evaluations = summary.evaluations() - before;
    record.result = nlopt_result_to_string(last);
    summary.starts.push_back(record);
  }

  evaluate.Finish(last == NLOPT_MAXEVAL_REACHED || summary.evaluations() >= options.max_evaluations,
                  last > 0, nlopt_result_to_string(last),
                  std::string("NLopt stopped with ") + nlopt_result_to_string(last));
  return summary;
}

std::string OptimizerSummary::BriefReport() const {
  char line[512];
  std::snprintf(line, sizeof line,
                "%s %s: %s after %d evaluations in %.1f s; objective %s -> %s (%d starts)",
                algorithm == "ceres" ? "Ceres" : "NLopt", algorithm.c_str(), ToString(termination),
                evaluations(), wall_time_s, Num(initial.value).c_str(), Num(best.value).c_str(),
                static_cast<int>(starts.size()));
  return line;
}

std::string OptimizerSummary::FullReport() const {
  std::string out = "\nCalibration report\n";
  char line[512];
  std::snprintf(line, sizeof line,
                "  %-28s %s\n  %-28s %s\n  %-28s %d (%d asked again, %d from a checkpoint)\n",
                "Algorithm", algorithm.c_str(), "Termination", message.c_str(), "Evaluations",
                evaluations(), cache_hits, replayed);
  out += line;
  std::snprintf(line, sizeof line, "  %-28s %s\n  %-28s %s (data %s + prior %s)\n  %-28s %.2f s\n",
                "Initial objective", Num(initial.value).c_str(), "Final objective",
                Num(best.value).c_str(), Num(best.data).c_str(), Num(best.prior).c_str(),
                "Wall time", wall_time_s);
  out += line;
  std::snprintf(line, sizeof line, "\n  %-28s %14s %14s %10s\n", "parameter", "initial", "final",
                "final u");
  out += line;
  for (std::size_t j = 0; j < names.size(); ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    std::snprintf(line, sizeof line, "  %-28s %14s %14s %10s\n", names[j].c_str(),
                  Num(initial.values.size() > k ? initial.values[k] : kNaN).c_str(),
                  Num(best.values.size() > k ? best.values[k] : kNaN).c_str(),
                  Num(best.u.size() > k ? best.u[k] : kNaN, "%.4f").c_str());
    out += line;
  }
  if (!std::isnan(fd_step)) {
    std::snprintf(line, sizeof line, "  %-28s %.3g (of each range)\n", "Finite-difference step",
                  fd_step);
    out += line;
  }
  if (!std::isnan(fd_shrink)) {
    std::snprintf(line, sizeof line,
                  "  %-28s noise-dominated: Gauss-Newton steps shortened to %.2g (more rocks per "
                  "run lower the noise)\n",
                  "Jacobian", fd_shrink);
    out += line;
  }
  out += "\n  start  evaluations  best objective  result\n";
  for (std::size_t s = 0; s < starts.size(); ++s) {
    std::snprintf(line, sizeof line, "  %5zu  %11d  %14s  %s\n", s, starts[s].evaluations,
                  Num(starts[s].best_value).c_str(), starts[s].result.c_str());
    out += line;
  }
  return out + BriefReport() + "\n";
}

}  // namespace talus::calibration
