#include "calibration/evaluator.hpp"

#include <sstream>
#include <stdexcept>

namespace talus::calibration {

Evaluator::Evaluator(const Objective& objective, const OptimizerOptions& options,
                     OptimizerSummary& summary)
    : objective_(objective),
      options_(options),
      summary_(summary),
      t0_(std::chrono::steady_clock::now()) {}

double Evaluator::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

bool Evaluator::out_of_evaluations() const {
  return summary_.evaluations() >= options_.max_evaluations;
}

Evaluation Evaluator::operator()(const Eigen::VectorXd& u) {
  for (const Evaluation& e : summary_.history)
    if (e.u.size() == u.size() && e.u == u) {
      ++summary_.cache_hits;
      return e;
    }
  const std::size_t index = summary_.history.size();
  Evaluation e;
  if (index < options_.replay.size()) {
    e = options_.replay[index];
    if (e.u.size() != u.size() || e.u != u) {
      std::ostringstream msg;
      msg << "checkpoint: evaluation " << index << " was at other parameters than this "
          << "calibration asks for: the checkpoint belongs to another calibration";
      throw std::runtime_error(msg.str());
    }
    ++summary_.replayed;
  } else {
    e = objective_.Evaluate(u);
  }
  summary_.history.push_back(e);
  summary_.history_start.push_back(start_);
  if (e.feasible && (!summary_.best.feasible || !(e.value >= summary_.best.value)))
    summary_.best = e;
  if (index == 0) summary_.initial = e;
  if (options_.on_evaluation) options_.on_evaluation(e, static_cast<int>(index));
  if (options_.max_time_s > 0 && elapsed_s() >= options_.max_time_s) out_of_time_ = true;
  return e;
}

std::optional<Evaluation> Evaluator::TryEvaluate(const Eigen::VectorXd& u) {
  // Points already known are answered even when stopped: they cost nothing.
  for (const Evaluation& e : summary_.history)
    if (e.u.size() == u.size() && e.u == u) {
      ++summary_.cache_hits;
      return e;
    }
  if (stopped()) return std::nullopt;
  try {
    return (*this)(u);
  } catch (...) {
    error_ = std::current_exception();
    return std::nullopt;
  }
}

void Evaluator::Finish(bool evaluations_spent, bool converged, const std::string& reason,
                       const std::string& failure) const {
  summary_.wall_time_s = elapsed_s();
  std::ostringstream msg;
  if (out_of_time_) {
    summary_.termination = Termination::kMaxTime;
    msg << "wall-time budget of " << options_.max_time_s << " s spent";
  } else if (evaluations_spent) {
    summary_.termination = Termination::kMaxEvaluations;
    msg << "evaluation budget of " << options_.max_evaluations << " spent";
  } else if (converged) {
    summary_.termination = Termination::kConvergence;
    msg << "converged (" << reason << ")";
  } else {
    summary_.termination = Termination::kFailure;
    msg << failure;
  }
  if (!summary_.IsSolutionUsable()) msg << "; no feasible evaluation";
  summary_.message = msg.str();
}

}  // namespace talus::calibration
