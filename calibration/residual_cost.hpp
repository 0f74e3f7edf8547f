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

// The central difference of step h in coordinate j at `at` (the evaluation at u), as the fit, its
// step choice and the covariance take it: the evaluations at the pair u -+ h e_j (CentralPair),
// with u's own standing in on a side that lies at u or is infeasible, and the pair's width.
// Nullopt when a side cannot be evaluated (budget spent, interrupted) or the width is 0.
struct CentralDifference {
  Evaluation lo, hi;
  double width = 0;
};
inline std::optional<CentralDifference> TakeCentralDifference(const EvaluateFn& evaluate,
                                                              const Evaluation& at, int j,
                                                              double h) {
  auto [lo, hi] = CentralPair(at.u, j, h);
  std::optional<Evaluation> a = lo[j] == at.u[j] ? at : evaluate(lo);
  std::optional<Evaluation> b = hi[j] == at.u[j] ? at : evaluate(hi);
  if (a && !a->feasible) a = at, lo = at.u;
  if (b && !b->feasible) b = at, hi = at.u;
  if (!a || !b || hi[j] == lo[j]) return std::nullopt;
  return CentralDifference{std::move(*a), std::move(*b), hi[j] - lo[j]};
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
      const std::optional<CentralDifference> d = TakeCentralDifference(evaluate_, *e, j, h_);
      if (!d) return false;
      jacobian.col(j) = (d->hi.residuals - d->lo.residuals) / d->width;
    }
    return true;
  }

 private:
  EvaluateFn evaluate_;
  int n_, m_;
  double h_;
};

}  // namespace talus::calibration
