#pragma once
// The optimiser of the calibration as one call: minimises the objective (objective.hpp) in the
// unit cube with the algorithm named in the options -- NLopt's (nlopt_optimizer.hpp) or Ceres'
// least squares ("ceres", least_squares.hpp) -- and returns the OptimizerSummary (optimizer.hpp).

#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"

namespace talus::calibration {

// Minimises the objective. Throws what options.on_evaluation throws; std::invalid_argument for
// invalid options (validate them first).
OptimizerSummary Optimize(const Objective& objective, const OptimizerOptions& options);

}  // namespace talus::calibration
