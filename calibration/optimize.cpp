#include "calibration/optimize.hpp"

#include <stdexcept>
#include <string>

#include "calibration/least_squares.hpp"
#include "calibration/nlopt_optimizer.hpp"

namespace talus::calibration {

OptimizerSummary Optimize(const Objective& objective, const OptimizerOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("Optimize: " + why);
  if (options.algorithm == "ceres") return OptimizeLeastSquares(objective, options);
  return OptimizeNlopt(objective, options);
}

}  // namespace talus::calibration
