#pragma once
// Numbers in the calibration's text reports (OptimizerSummary, Uncertainty).

#include <string>

#include "common/format.hpp"

namespace talus::calibration {

// v in the printf `format`; "-" for NaN (a value that does not exist, e.g. a skipped start).
inline std::string Num(double v, const char* format = "%.6g") {
  return FormatOrMissing(v, format, "-");
}

}  // namespace talus::calibration
