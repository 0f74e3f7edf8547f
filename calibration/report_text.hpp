#pragma once
// Numbers in the calibration's text reports (OptimizerSummary, Uncertainty).

#include <cmath>
#include <cstdio>
#include <string>

namespace talus::calibration {

// v in the printf `format`; "-" for NaN (a value that does not exist, e.g. a skipped start).
inline std::string Num(double v, const char* format = "%.6g") {
  if (std::isnan(v)) return "-";
  char b[64];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

}  // namespace talus::calibration
