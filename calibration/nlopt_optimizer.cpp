#include "calibration/nlopt_optimizer.hpp"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "calibration/evaluator.hpp"

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

OptimizerSummary OptimizeNlopt(const Objective& objective, const OptimizerOptions& options) {
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
    if (!run.opt) throw std::runtime_error("OptimizeNlopt: NLopt could not create its optimiser");
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

}  // namespace talus::calibration
