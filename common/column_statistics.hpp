#pragma once
// Exact summaries of columns of numbers that may be too many to hold in memory: each column's
// count, sum in order, finite range and nearest-rank percentiles, from a source that can be read
// again (a CSV file of the run). The outputs read their per-rock files back this way (report.html,
// evaluation lines, barriers), so their memory does not grow with the number of rocks.

#include <cstddef>
#include <functional>
#include <limits>
#include <vector>

namespace talus {

// A source calls emit(column, value) for each of its values, in the same order on every call.
using ColumnSink = std::function<void(std::size_t column, double value)>;
using ColumnSource = std::function<void(const ColumnSink& emit)>;

struct ColumnStatistics {
  long count = 0;   // values, NaN and infinities included
  double sum = 0;   // of all values, summed in the source's order
  long finite = 0;  // finite values
  double min = std::numeric_limits<double>::quiet_NaN();  // smallest finite value; NaN when none
  double max = std::numeric_limits<double>::quiet_NaN();  // largest finite value; NaN when none
  // NearestRankPercentile (common/statistics.hpp) of the finite values, one per requested
  // percentile, in the order requested; NaN when there is no finite value.
  std::vector<double> percentiles;

  // sum / count, as Mean (common/statistics.hpp) of the values in the source's order: NaN when
  // there is no value or one is NaN.
  double mean() const;
};

// Default memory budget of SummarizeColumns for values and histograms.
inline constexpr std::size_t kColumnStatisticsBudgetBytes = std::size_t{1} << 20;

// The statistics of the columns 0 .. columns-1 of `source` at the percentiles `percents`
// (0 < p <= 100). The source is read once when its finite values fit in `budget_bytes` (8 bytes
// each), and the percentiles are selected in memory. Otherwise each percentile is found exactly by
// reading the source again: 4096-bin histograms of successive 12-bit digits of the values' ordered
// bit patterns narrow it to a range that fits the budget, and that range is read and selected. Both
// give the same values (a zero is returned as +0 from the second). Memory is at most twice the
// budget (vectors grow by doubling) and at least one 32 KiB histogram, whatever the number of
// values. Throws what the source throws, and std::runtime_error when the source gives other values
// when read again.
std::vector<ColumnStatistics> SummarizeColumns(
    const ColumnSource& source, std::size_t columns, const std::vector<double>& percents,
    std::size_t budget_bytes = kColumnStatisticsBudgetBytes);

}  // namespace talus
