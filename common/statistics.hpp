#pragma once
// Statistics of samples shared by the output formats.

#include <cstddef>
#include <vector>

namespace talus {

// The arithmetic mean, summed in order; NaN when `values` is empty.
double Mean(const std::vector<double>& values);

// The p-quantile (0 <= p <= 1) of ascending `sorted` (not empty), interpolated between order
// statistics (Hyndman & Fan 1996, definition 7, R's default).
double SortedQuantile(const std::vector<double>& sorted, double p);

// The nearest rank of percentile p (0 < p <= 100) among n > 0 values: max(1, ceil(p/100 n)).
std::size_t NearestRank(double p, std::size_t n);

// Nearest-rank percentile (0 < p <= 100) of `values`: the ceil(p/100 n)-th smallest of the n finite
// values (Hyndman & Fan 1996, definition 1); NaN when there is none.
double NearestRankPercentile(std::vector<double> values, double p);

}  // namespace talus
