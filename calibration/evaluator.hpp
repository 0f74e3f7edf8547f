#pragma once
// The bookkeeping every optimiser shares (nlopt_optimizer.cpp, least_squares.cpp), on the
// vocabulary of optimizer.hpp: runs the objective for the optimiser and keeps the record in an
// OptimizerSummary -- every evaluation in order, its start, the best feasible one --, answers a
// point asked for again from the history (the objective is deterministic; evaluations already in
// the summary's history when it starts are answered too), serves the evaluations of a checkpoint
// (OptimizerOptions::replay) in order without running a rock, calls
// OptimizerOptions::on_evaluation, and watches the budget. The covariance (covariance.cpp) uses it
// as its cache of a calibration's evaluations.

#include <Eigen/Core>
#include <chrono>
#include <exception>
#include <optional>
#include <string>

#include "calibration/optimizer.hpp"

namespace talus::calibration {

class Evaluator {
 public:
  Evaluator(const Objective& objective, const OptimizerOptions& options, OptimizerSummary& summary);

  // The evaluation at u, from the history, the replay or a run of the objective. Throws what the
  // objective or on_evaluation throws, and std::runtime_error when the replay's next evaluation
  // is at another point (the checkpoint belongs to another calibration).
  Evaluation operator()(const Eigen::VectorXd& u);
  // The same, for callbacks that must not throw: nullopt once stopped (the budget is spent, or an
  // exception was caught and kept for Rethrow), and no new evaluation is run then.
  std::optional<Evaluation> TryEvaluate(const Eigen::VectorXd& u);

  void set_start(int start) { start_ = start; }
  double elapsed_s() const;
  bool out_of_time() const { return out_of_time_; }
  bool out_of_evaluations() const;
  bool stopped() const { return out_of_time_ || out_of_evaluations() || error_ != nullptr; }
  void Rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }
  // Closes the record when the optimiser has returned: the wall time, and the termination with its
  // message -- the time budget first, then the evaluation budget (`evaluations_spent`, as the
  // optimiser counts it), then convergence (`converged`, because of `reason`), else a failure
  // (`failure` says how the optimiser stopped).
  void Finish(bool evaluations_spent, bool converged, const std::string& reason,
              const std::string& failure) const;

 private:
  const Objective& objective_;
  const OptimizerOptions& options_;
  OptimizerSummary& summary_;
  std::chrono::steady_clock::time_point t0_;
  int start_ = 0;
  bool out_of_time_ = false;
  std::exception_ptr error_;
};

}  // namespace talus::calibration
