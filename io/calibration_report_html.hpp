#pragma once
// report.html of `talus calibrate`: one self-contained page (html_page.hpp) with the warnings, the
// fitted parameters with their uncertainty and the reason a value is not supported, the objective
// per observation kind before and after, the convergence, each parameter's profile, the observed
// against the simulated, the held-out runs and the folds of a cross-validation. Everything on it
// comes from calibration.json and the plots written beside it.

#include <string>
#include <vector>

namespace talus::io {

struct CalibrationReportInput {
  std::string calibration_json;                 // calibration.json's text
  std::string convergence_svg;                  // convergence.svg
  std::vector<std::string> observed_simulated;  // observed_vs_simulated_<kind>.svg, in order
};

std::string CalibrationReportHtml(const CalibrationReportInput& input);

}  // namespace talus::io
