#pragma once
// The outputs of evaluation lines (docs/scenes.md): evaluation_lines.csv, one row per rock and line
// crossed, streamed in rock order and complete or absent; and the per-line summary
// (evaluation_lines_summary.csv, summary.json, report.html), computed from that file read back
// once it is complete, so that a run split into parts or ranks gives the same numbers.

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/column_statistics.hpp"
#include "ensemble/evaluation_lines.hpp"
#include "ensemble/outcome.hpp"
#include "ensemble/release.hpp"

namespace talus::io {

class EvaluationLinesCsvWriter {
 public:
  // Opens a temporary file next to `path` and writes the header. `lines` and `release` name each
  // row's line and run; both must outlive the writer. Throws std::runtime_error.
  EvaluationLinesCsvWriter(const std::string& path,
                           const std::vector<ensemble::EvaluationLine>& lines,
                           const ensemble::ReleaseSpec& release);
  EvaluationLinesCsvWriter(const EvaluationLinesCsvWriter&) = delete;
  EvaluationLinesCsvWriter& operator=(const EvaluationLinesCsvWriter&) = delete;

  // A row per line the rock crossed (RockOutcome::line_crossings), in line order.
  void Write(const ensemble::RockOutcome& rock);
  void Commit();  // flushes, closes and renames into place

  static const char* Header();

 private:
  AtomicTextFile file_;
  const std::vector<ensemble::EvaluationLine>& lines_;
  const ensemble::ReleaseSpec& release_;
};

// The percentiles of CrossingStatistics after its mean: median, 90 %, 95 %, 99 % and largest.
inline const std::vector<double> kCrossingPercents = {50, 90, 95, 99, 100};

// Mean, nearest-rank percentiles (common/statistics.hpp NearestRankPercentile) and largest value of
// one quantity over the rocks that crossed a line; NaN when none did.
struct CrossingStatistics {
  static constexpr std::array<const char*, 6> kNames = {"mean", "p50", "p90", "p95", "p99", "max"};
  std::array<double, 6> values{};  // in the order of kNames
};

// One line's summary over the rocks of a run.
struct EvaluationLineSummary {
  std::string name;
  double length_m = 0;
  long rocks = 0;                  // rocks of the run
  long crossed = 0;                // rocks that crossed the line
  double passing_probability = 0;  // crossed / rocks
  CrossingStatistics speed_m_s, energy_J, com_height_m, bounce_height_m;
};

// The statistics of `values` (in any order; the mean is summed in the order given).
CrossingStatistics StatisticsOf(const std::vector<double>& values);
// The same from a column summarised at kCrossingPercents (common/column_statistics.hpp).
CrossingStatistics CrossingStatisticsOf(const ColumnStatistics& column);

// The summary of every line from a complete evaluation_lines.csv of a run of `rocks` rocks, read
// record by record, and again as SummarizeColumns needs: memory is bounded by `budget_bytes`, not
// by the rows. Throws InputError naming the file and line when a row is not one the writer writes.
std::vector<EvaluationLineSummary> SummarizeEvaluationLines(
    const std::string& csv_path, const std::vector<ensemble::EvaluationLine>& lines, long rocks,
    std::size_t budget_bytes = kColumnStatisticsBudgetBytes);

// evaluation_lines_summary.csv: a header and one row per line.
std::string EvaluationLinesSummaryCsv(const std::vector<EvaluationLineSummary>& summary);

}  // namespace talus::io
