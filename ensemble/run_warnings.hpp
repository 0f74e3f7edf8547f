#pragma once
// What a finished ensemble's results are worth where they are censored or weak, in words a user
// acts on: the warnings `talus simulate` and `talus merge` print, write into summary.json and show
// at the top of report.html (docs/scenes.md, "Warnings"). Each names the count, the share, what it
// censors and the knob to turn. Thresholds:
//  - rocks still moving at max_time: any (their run-out, deposit and reach are where they were cut
//    off, short of where they would stop: every such rock biases the run-out distribution low);
//  - rocks that left the DEM: any (their run-outs end at its edge, and the reach beyond is
//  unknown);
//  - failed rocks: any (numerical trouble; they are missing from the results);
//  - rocks that stayed at release: more than kStayedShare of them (a few blocks landing flat where
//    mu(s) exceeds the slope's tangent are physics; many say the release or the ground is off).

#include <string>
#include <vector>

#include "ensemble/runner.hpp"
#include "solver/options.hpp"

namespace talus::ensemble {

inline constexpr double kStayedShare = 0.05;

std::vector<std::string> RunWarnings(const EnsembleReport& report, const SolverOptions& options);

}  // namespace talus::ensemble
