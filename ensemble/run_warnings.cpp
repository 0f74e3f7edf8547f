#include "ensemble/run_warnings.hpp"

#include <cstdio>

namespace talus::ensemble {
namespace {

// "<n> of <total> rocks (<share> %)".
std::string Count(long n, long total) {
  char text[96];
  std::snprintf(text, sizeof text, "%ld of %ld rocks (%.1f %%)", n, total,
                total > 0 ? 100.0 * double(n) / double(total) : 0.0);
  return text;
}

}  // namespace

std::vector<std::string> RunWarnings(const EnsembleReport& report, const SolverOptions& options) {
  std::vector<std::string> out;
  const long total = report.rocks;
  if (const long n = report.count(EndReason::kMaxTime); n > 0) {
    char limit[48];
    std::snprintf(limit, sizeof limit, "%g s", options.max_time_s);
    out.push_back(Count(n, total) + " were still moving at max_time_s = " + limit +
                  ": their run-out, deposit and reach are where they were cut off, short of where "
                  "they would stop (censored; run-out statistics are biased low). Raise "
                  "[solver] max_time_s.");
  }
  if (const long n = report.count(EndReason::kLeftDomain); n > 0)
    out.push_back(Count(n, total) +
                  " left the DEM: their run-outs end at its edge (censored) and the reach "
                  "probability near the edge is a lower bound. Use a DEM that contains the "
                  "run-outs.");
  if (const long n = report.count(EndReason::kFailed); n > 0)
    out.push_back(Count(n, total) +
                  " failed (numerical trouble, ending 'failed' in rocks.csv): they are missing "
                  "from the rasters and statistics.");
  if (total > 0 && double(report.stayed_at_release) > kStayedShare * double(total))
    out.push_back(Count(report.stayed_at_release, total) +
                  " never got further than their own length from the release (more than 5 %): "
                  "the ground held them (mu(s) above the slope's tangent). Check the release "
                  "points and the ground there.");
  return out;
}

}  // namespace talus::ensemble
