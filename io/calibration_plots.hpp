#pragma once
// The plots of `talus calibrate` as small, deterministic SVG files (docs/calibration.md): the
// convergence of the objective over the evaluations, the observed against the simulated median of
// each scalar observation kind before and after the fit, and each parameter's profile.

#include <string>
#include <vector>

#include "calibration/optimizer.hpp"
#include "fieldobs/validation.hpp"

namespace talus::io {

// Every feasible evaluation's objective (dots) and the best so far (line), against the evaluation.
std::string ConvergenceSvg(const calibration::OptimizerSummary& summary);

// For the scored observations of `kind` (a scalar kind): observed (x) against the simulated
// median (y), before (grey) and after (blue) the fit, with the 1:1 line. `before` and `after` are
// the same observations scored with the initial and the fitted parameters.
std::string ObservedSimulatedSvg(const std::string& kind,
                                 const std::vector<fieldobs::ObservationScore>& before,
                                 const std::vector<fieldobs::ObservationScore>& after);

// A parameter's profile: the objective (y) along the parameter's values (x) with the others at
// the optimum, the fitted value as a dashed line; "flat: unidentified" in the title when it is.
std::string ProfileSvg(const std::string& name, const std::string& unit,
                       const std::vector<double>& values, const std::vector<double>& objective,
                       double fitted, bool identified);

}  // namespace talus::io
