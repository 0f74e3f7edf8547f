#pragma once
// The calibration's residual vector (Evaluation::residuals, objective.hpp) as a Ceres cost
// function, shared by the least-squares fit (least_squares.cpp) and the covariance
// (covariance.cpp): derivatives are central differences with an absolute step h in unit
// coordinates (a fraction of each parameter's range), moved inside the box at a bound (one-sided
// there). Ceres' own NumericDiffCostFunction steps relative to |x| and knows no bounds, hence a
// cost function of our own. Inside the calibration module only.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <functional>
#include <optional>
#include <utility>

#include "calibration/objective.hpp"

namespace talus::calibration {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
// An evaluation at u, or nullopt when none can be had (budget spent, stopped by an exception).
using EvaluateFn = std::function<std::optional<Evaluation>(const Eigen::VectorXd&)>;

// The pair u -+ h e_j of a central difference, moved inside [0, 1] at a bound.
inline std::pair<Eigen::VectorXd, Eigen::VectorXd> CentralPair(const Eigen::VectorXd& u, int j,
                                                               double h) {
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

}  // namespace talus::calibration
