#pragma once
// Statistics of samples shared by the output formats.

#include <vector>

namespace talus {

// Nearest-rank percentile (0 < p <= 100) of `values`: the ceil(p/100 n)-th smallest of the n finite
// values (Hyndman & Fan 1996, definition 1); NaN when there is none.
double NearestRankPercentile(std::vector<double> values, double p);

}  // namespace talus
