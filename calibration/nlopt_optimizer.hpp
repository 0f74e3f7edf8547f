#pragma once
// The NLopt back-end of the calibration's optimiser (optimizer.hpp): its derivative-free methods
// by name -- local BOBYQA and Sbplx, global CRS2-LM, DIRECT-L and ISRES -- in the unit cube, from
// each start in turn (StartPoints), each start with its share of the evaluations left. Time is
// watched by the Evaluator after each evaluation, not by NLopt's clock, so that the path does not
// depend on when NLopt looks at it.

#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"

namespace talus::calibration {

// options.algorithm one of the NLopt names. Called by Optimize (optimize.hpp), which checks the
// options. Throws what options.on_evaluation throws.
OptimizerSummary OptimizeNlopt(const Objective& objective, const OptimizerOptions& options);

}  // namespace talus::calibration
